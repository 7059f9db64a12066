// Exact Euclidean distance transform of a binary grid.
//
// Felzenszwalb & Huttenlocher, "Distance Transforms of Sampled Functions",
// Theory of Computing 8 (2012): the squared distance is separable, so a 1D
// lower-envelope-of-parabolas pass over every column and then every row gives
// the exact result in O(width * height).
#pragma once

#include <vector>

namespace pf {

/// Squared distance, in cells, from every cell to the nearest cell whose
/// `is_source` flag is set (row-major, width * height). Cells with no source
/// at all in the grid get +infinity.
std::vector<float> squaredDistanceTransform(const std::vector<bool>& is_source, int width,
                                            int height);

}  // namespace pf
