#include "pf_localization/ros/localizer/floors.h"

#include <std_msgs/String.h>

#include <utility>

#include "pf_localization/core/map/map_loader.h"
#include "pf_localization/ros/input/conversions.h"

namespace pf_ros {
namespace {

constexpr double kSearchPeriod = 0.2;  // s of wall time between two looks at the search's verdict

}  // namespace

std::optional<pf::FloorsFile> Floors::read(const std::string& path) {
  try {
    pf::FloorsFile file = pf::loadFloorsFile(path);
    ROS_INFO("pf_node: floors_file %s: %zu floors (%s), initial floor '%s'", path.c_str(),
             file.floors.size(), file.names().c_str(), file.floors[file.initial].name.c_str());
    return file;
  } catch (const pf::FloorsFileError& e) {
    ROS_FATAL("pf_node: ~floors_file: %s", e.what());
    return std::nullopt;
  }
}

Floors::Floors(pf::FloorsFile file, LiveLocalizer* live, UpdateScheduler* scheduler,
               ToGlobal to_global, ros::NodeHandle& nh)
    : file_(std::move(file)),
      live_(live),
      scheduler_(scheduler),
      to_global_(std::move(to_global)),
      kept_(file_.floors.size()),
      floor_pub_(nh.advertise<std_msgs::String>("pf_floor", 1, true)),
      service_(nh.advertiseService("change_floor", &Floors::onChangeFloor, this)),
      search_timer_(nh.createWallTimer(
          ros::WallDuration(kSearchPeriod), [this](const ros::WallTimerEvent&) { checkSearch(); },
          false, false)) {
  live_->useFloors([this] { return search(); });
}

std::unique_ptr<Floors> Floors::create(std::optional<pf::FloorsFile> file, LiveLocalizer* live,
                                       UpdateScheduler* scheduler, ToGlobal to_global,
                                       ros::NodeHandle& nh) {
  if (!file) return nullptr;
  auto floors =
      std::make_unique<Floors>(std::move(*file), live, scheduler, std::move(to_global), nh);
  floors->start();
  return floors;
}

Floors::~Floors() {
  live_->useFloors({});
  search_timer_.stop();
  if (search_) scheduler_->withFilter([&] { stopSearch(); });
}

bool Floors::start() {
  // A pose saved on a floor is used there (decideSavedPose: and only there).
  const std::string saved = scheduler_->withFilter([&] { return live_->savedPoseFloor(); });
  std::size_t index = file_.initial;
  if (const std::optional<std::size_t> found = file_.find(saved); found && !saved.empty()) {
    index = *found;
    ROS_INFO("pf_node: starting on floor '%s', where the earlier run saved its pose",
             saved.c_str());
  }
  const Outcome outcome = change(file_.floors[index].name, std::nullopt);
  if (!outcome.ok) ROS_ERROR("pf_node: %s", outcome.message.c_str());
  return outcome.ok;
}

std::string Floors::current() const {
  return current_ && !search_ ? file_.floors[*current_].name : "";
}

Floors::Outcome Floors::change(
    const std::string& name, const std::optional<geometry_msgs::PoseWithCovarianceStamped>& pose) {
  const std::optional<std::size_t> index = file_.find(name);
  if (!index) return {false, "no floor '" + name + "' (the floors: " + file_.names() + ")"};
  std::optional<geometry_msgs::PoseWithCovarianceStamped> global;
  if (pose) {
    geometry_msgs::PoseWithCovarianceStamped given = *pose;
    if (given.header.stamp.isZero()) given.header.stamp = ros::Time::now();
    global = to_global_(given);
    if (!global) return {false, "the pose's frame '" + given.header.frame_id + "' is not in tf"};
  }
  if (search_) {  // a floor given ends a search of every floor
    search_timer_.stop();
    scheduler_->withFilter([&] { stopSearch(); });
    ROS_INFO("pf_node: the search of every floor ends: change_floor names the floor");
  }
  return moveTo(*index, global);
}

Floors::Outcome Floors::moveTo(
    std::size_t index, const std::optional<geometry_msgs::PoseWithCovarianceStamped>& global) {
  const std::string& name = file_.floors[index].name;
  std::optional<LiveLocalizer::BuiltMap> built;
  if (index != current_) {
    std::string error;
    built = mapOf(index, &error);
    if (!built) return {false, "floor '" + name + "': " + error};
  }
  std::optional<pf::PreparedMap> replaced;
  const bool swaps = built.has_value();
  const bool ok = scheduler_->withFilter(
      [&] { return live_->changeFloor(std::move(built), name, global, &replaced); });
  // A built map is always installed (changeFloor refuses only the pose).
  if (swaps) {
    if (current_) kept_[*current_].map = std::move(replaced);
    current_ = index;
  }
  publishFloor();
  const std::string where = "on floor '" + name + "'";
  if (!ok) return {false, where + ", but the pose was refused (logged): global localization"};
  return {true, where + (global ? ", at the pose given" : ": global localization")};
}

std::optional<LiveLocalizer::BuiltMap> Floors::mapOf(std::size_t index, std::string* error) {
  Kept& kept = kept_[index];
  LiveLocalizer::BuiltMap built;
  if (kept.map) {
    built.ready.map = std::move(kept.map);
    kept.map.reset();
    built.ready.info = kept.info;
    built.signature = kept.signature;
    built.kept = true;
    return built;
  }
  nav_msgs::OccupancyGrid map;
  try {
    map = toMsg(pf::loadMap(file_.floors[index].map));
  } catch (const pf::MapLoadError& e) {
    *error = e.what();
    return std::nullopt;
  }
  map.header.stamp = ros::Time::now();
  built = live_->buildMap(map, *scheduler_);
  if (!built.ready.map) {
    *error = built.ready.error;
    return std::nullopt;
  }
  kept.info = built.ready.info;
  kept.signature = built.signature;
  ROS_INFO("pf_node: floor '%s': map %s prepared; kept for the rides back",
           file_.floors[index].name.c_str(), file_.floors[index].map.c_str());
  return built;
}

void Floors::publishFloor() {
  std_msgs::String msg;
  msg.data = current();
  floor_pub_.publish(msg);
}

bool Floors::search() {
  // Every floor's map afresh: the kept ones' change layers stay out of
  // filters that may be on the wrong floor.
  std::vector<pf::PreparedMap> maps;
  for (const pf::Floor& floor : file_.floors) {
    std::string error;
    try {
      nav_msgs::OccupancyGrid map = toMsg(pf::loadMap(floor.map));
      LiveLocalizer::BuiltMap built = live_->buildMap(map, *scheduler_);
      error = built.ready.error;
      if (built.ready.map) maps.push_back(std::move(*built.ready.map));
    } catch (const pf::MapLoadError& e) {
      error = e.what();
    }
    if (!error.empty()) {
      ROS_ERROR("pf_node: no search of every floor: floor '%s': %s", floor.name.c_str(),
                error.c_str());
      return false;
    }
  }
  scheduler_->withFilter([&] {
    stopSearch();  // one running starts over
    std::vector<std::string> names;
    for (const pf::Floor& floor : file_.floors) names.push_back(floor.name);
    search_ = std::make_unique<pf::FloorSearch>(live_->filterParams(), std::move(maps), names);
    live_->observeUpdates(
        [this](const pf::Pose2& odom, const pf::ScanGroup& scans, const ros::Time& stamp) {
          search_->update(odom, scans);
          search_stamp_ = stamp;
        });
    live_->showFloor("unknown", true);
  });
  std_msgs::String unknown;  // empty: no floor
  floor_pub_.publish(unknown);
  search_reason_.clear();
  search_timer_.start();
  ROS_INFO("pf_node: global localization on every floor (%s)", file_.names().c_str());
  return true;
}

void Floors::stopSearch() {
  live_->observeUpdates({});
  search_.reset();
}

void Floors::checkSearch() {
  if (!search_) return;
  pf::FloorSearch::Verdict verdict;
  std::optional<geometry_msgs::PoseWithCovarianceStamped> pose;
  scheduler_->withFilter([&] {
    verdict = search_->verdict();
    if (!verdict.floor) return;
    // Where the robot is on that floor: its search's estimate at the last
    // update, moved on by the odometry since (setInitialPose).
    const pf::ParticleFilter& found = search_->filter(*verdict.floor);
    pose.emplace();
    pose->header.stamp = search_stamp_;
    pose->header.frame_id = live_->globalFrame();
    pose->pose.pose = toPoseMsg(found.estimate().pose);
    pose->pose.covariance = toRosCovariance(found.confidence().covariance);
    stopSearch();
  });
  if (verdict.reason != search_reason_) {
    ROS_INFO("pf_node: the search of every floor: %s", verdict.reason.c_str());
    search_reason_ = verdict.reason;
  }
  if (!verdict.floor) return;
  search_timer_.stop();
  const Outcome outcome = moveTo(*verdict.floor, pose);
  ROS_INFO("pf_node: the search of every floor found floor '%s': %s",
           file_.floors[*verdict.floor].name.c_str(), outcome.message.c_str());
}

bool Floors::onChangeFloor(pf_localization::ChangeFloor::Request& req,
                           pf_localization::ChangeFloor::Response& res) {
  std::optional<geometry_msgs::PoseWithCovarianceStamped> pose;
  if (!req.initial_pose.header.frame_id.empty()) pose = req.initial_pose;
  const Outcome outcome = change(req.floor, pose);
  res.success = outcome.ok;
  res.message = outcome.message;
  if (outcome.ok) {
    ROS_INFO("pf_node: change_floor: %s", outcome.message.c_str());
  } else {
    ROS_WARN("pf_node: change_floor: %s", outcome.message.c_str());
  }
  return true;
}

}  // namespace pf_ros
