// Exact Euclidean distance transform of a binary grid.
//
// The squared distance is separable: the distance to the nearest source in
// each column, then along each row the lower envelope of the parabolas
// rooted at the columns' squared distances, gives the exact result in
// O(width * height). The column pass is the first phase of Meijster,
// Roerdink & Hesselink, "A General Algorithm for Computing Distance
// Transforms in Linear Time" (2000): two sweeps, done a row at a time so that
// memory is read in order. The row pass is Felzenszwalb & Huttenlocher,
// "Distance Transforms of Sampled Functions", Theory of Computing 8 (2012).
// Apart from a row of scratch, the result is the only memory it takes: each
// fresh page costs a page fault, and a map at 2 cm has millions of cells.
#pragma once

#include <vector>

namespace pf {

/// Squared distance, in cells, from every cell to the nearest cell whose
/// `is_source` flag is set (row-major, width * height). Cells with no source
/// at all in the grid get +infinity.
std::vector<float> squaredDistanceTransform(const std::vector<bool>& is_source, int width,
                                            int height);

}  // namespace pf
