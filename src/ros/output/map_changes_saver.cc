#include "pf_localization/ros/output/map_changes_saver.h"

#include <fcntl.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include "pf_localization/core/map/map_change_file.h"

namespace pf_ros {
namespace {

std::string systemError(const std::string& what) { return what + ": " + std::strerror(errno); }

// The whole of `fd`'s `bytes` written and flushed to the disk.
bool writeAll(int fd, const std::string& bytes) {
  for (std::size_t done = 0; done < bytes.size();) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return ::fsync(fd) == 0;
}

}  // namespace

std::string defaultMapChangesPath(const std::string& node_name) {
  std::string name = node_name;
  while (!name.empty() && name.front() == '/') name.erase(name.begin());
  for (char& c : name) c = c == '/' ? '_' : c;
  if (name.empty()) name = "pf_node";
  const char* ros_home = std::getenv("ROS_HOME");
  const char* home = std::getenv("HOME");
  const std::string dir = ros_home && *ros_home ? ros_home
                          : home && *home       ? std::string(home) + "/.ros"
                                                : ".";
  return dir + "/" + name + ".map_changes";
}

std::string floorMapChangesPath(const std::string& path, const std::string& floor) {
  std::string name;
  for (const char c : floor) {
    if (std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_') {
      name += c;
    } else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", static_cast<unsigned char>(c));
      name += hex;
    }
  }
  const std::filesystem::path file(path);
  const std::string ext = file.filename().extension().string();
  if (ext.empty() || ext == file.filename().string()) return path + "." + name;
  return path.substr(0, path.size() - ext.size()) + "." + name + ext;
}

std::string writeFileAtomically(const std::string& path, const std::string& bytes) {
  const std::filesystem::path target(path);
  std::error_code ec;
  if (target.has_parent_path()) std::filesystem::create_directories(target.parent_path(), ec);
  const std::string temp = path + ".tmp" + std::to_string(::getpid());
  const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return systemError("cannot create " + temp);
  const bool written = writeAll(fd, bytes);
  const std::string error = written ? "" : systemError("cannot write " + temp);
  if (::close(fd) != 0 || !written) {
    std::remove(temp.c_str());
    return error.empty() ? systemError("cannot write " + temp) : error;
  }
  if (std::rename(temp.c_str(), path.c_str()) != 0) {
    const std::string renamed = systemError("cannot rename " + temp + " to " + path);
    std::remove(temp.c_str());
    return renamed;
  }
  return "";
}

MapChangesRestore restoreMapChanges(const std::string& path, const std::string& signature,
                                    pf::ParticleFilter* filter) {
  using Level = MapChangesRestore::Level;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec) && !ec) {
    return {Level::kInfo, "no map changes saved in " + path + ": the layer starts empty", false};
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    return {
        Level::kWarn,
        systemError("cannot read the map changes saved in " + path) + ": the layer starts empty",
        false};
  }
  std::ostringstream bytes;
  bytes << in.rdbuf();
  const pf::MapChangesFileContents file = pf::readMapChangesFile(bytes.str());
  if (!file.error.empty()) {
    return {Level::kWarn,
            "map changes file " + path + " refused (" + file.error + "): the layer starts empty",
            false};
  }
  if (file.map_signature != signature) {
    return {Level::kWarn,
            "the map changes in " + path + " were learned on another map (" + file.map_signature +
                "; this one: " + signature + "): the layer starts empty",
            false};
  }
  const std::string error = filter->restoreMapChanges(file.state);
  if (!error.empty()) {
    return {Level::kWarn,
            "map changes file " + path + " refused (" + error + "): the layer starts empty", false};
  }
  const pf::MapChangeLayer::Summary s = filter->mapChanges()->summary();
  std::ostringstream msg;
  msg << "restored the map changes learned on this map from " << path << ": " << s.added
      << " cells new, " << s.removed << " gone, of " << s.seen << " seen, from "
      << filter->mapChanges()->scans() << " scans";
  return {Level::kInfo, msg.str(), true};
}

MapChangesSaver::MapChangesSaver(std::string path, double rate)
    : path_(std::move(path)), rate_(rate) {}

void MapChangesSaver::setMap(const std::string& signature, std::size_t saved_scans,
                             const std::string& path) {
  signature_ = signature;
  current_path_ = path.empty() ? path_ : path;
  copied_scans_ = saved_scans;
  dirty_ = false;
}

void MapChangesSaver::offer(const pf::MapChangeLayer* layer, const ros::WallTime& now,
                            bool now_anyway) {
  if (!enabled() || layer == nullptr) return;
  if (!dirty_ && layer->scans() == copied_scans_) return;
  if (!now_anyway && !last_copy_.isZero() && now >= last_copy_ &&
      (now - last_copy_).toSec() < 1.0 / rate_) {
    return;
  }
  std::string bytes = pf::mapChangesFile(*layer, signature_);
  copied_scans_ = layer->scans();
  dirty_ = false;
  last_copy_ = now;
  std::lock_guard<std::mutex> lock(mutex_);
  pending_[current_path_.empty() ? path_ : current_path_] = std::move(bytes);
}

std::string MapChangesSaver::writePending() {
  std::map<std::string, std::string> files;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    files.swap(pending_);
  }
  std::string errors;
  for (auto& [path, bytes] : files) {
    const std::string error = writeFileAtomically(path, bytes);
    if (error.empty()) continue;
    errors += (errors.empty() ? "" : "; ") + error;
    std::lock_guard<std::mutex> lock(mutex_);
    pending_.emplace(path, std::move(bytes));  // unless a newer copy came
  }
  return errors;
}

}  // namespace pf_ros
