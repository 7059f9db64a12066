#include "pf_localization/core/filter/prepared_map.h"

#include <stdexcept>
#include <utility>

#include "pf_localization/core/filter/particle_filter.h"

namespace pf {

PreparedMap PreparedMap::build(OccupancyGrid grid, const Recipe& recipe) {
  if (grid.empty()) throw std::invalid_argument("the map is empty");
  std::unique_ptr<SensorModel> model = makeSensorModel(std::move(grid), recipe.params);
  for (double range_max : recipe.ranges) model->warmUp(range_max);
  const DistanceField& field = model->field();
  BeamScreen::MapParts screen = BeamScreen::prepare(field);
  std::vector<MapSymmetry> symmetries = findMapSymmetries(field);
  return {std::move(model), std::move(screen), std::move(symmetries), recipe.params};
}

}  // namespace pf
