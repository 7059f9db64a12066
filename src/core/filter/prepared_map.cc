#include "pf_localization/core/filter/prepared_map.h"

#include <optional>
#include <stdexcept>
#include <utility>

#include "pf_localization/core/filter/particle_filter.h"
#include "pf_localization/core/util/worker_pool.h"

namespace pf {

PreparedMap PreparedMap::build(OccupancyGrid grid, const Recipe& recipe) {
  if (grid.empty()) throw std::invalid_argument("the map is empty");
  std::unique_ptr<SensorModel> model = makeSensorModel(std::move(grid), recipe.params);
  const DistanceField& field = model->field();
  // What is built on the field, in two independent tasks so that a second
  // core takes one: the tables and the screening's parts, and the look-alike
  // search (the same result on any number of threads).
  std::optional<BeamScreen::MapParts> screen;
  std::vector<MapSymmetry> symmetries;
  auto build = [&](std::size_t k) {
    if (k == 0) {
      for (double range_max : recipe.ranges) model->warmUp(range_max);
      screen.emplace(BeamScreen::prepare(field));
    } else {
      symmetries = findMapSymmetries(field);
    }
  };
  WorkerPool::instance().run(resolvedThreads(recipe.params.threads), 2, build);
  return {std::move(model), std::move(*screen), std::move(symmetries), recipe.params};
}

}  // namespace pf
