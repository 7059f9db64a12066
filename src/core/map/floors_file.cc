#include "pf_localization/core/map/floors_file.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>

namespace pf {
namespace {

namespace fs = std::filesystem;

// A floor's field `field` as a non-empty string; `where` names the floor.
std::string text(const YAML::Node& floor, const char* field, const std::string& where) {
  const YAML::Node n = floor[field];
  if (!n || !n.IsScalar() || n.Scalar().empty()) {
    throw FloorsFileError(where + ": needs a non-empty '" + field + "'");
  }
  return n.Scalar();
}

Floor readFloor(const YAML::Node& node, const fs::path& folder, const std::string& where) {
  if (!node.IsMap()) throw FloorsFileError(where + ": must be a map with 'name' and 'map'");
  Floor f{text(node, "name", where), text(node, "map", where)};
  const fs::path map(f.map);
  f.map = (map.is_absolute() ? map : folder / map).lexically_normal().string();
  std::error_code error;
  if (!fs::is_regular_file(f.map, error)) {
    throw FloorsFileError(where + " ('" + f.name + "'): no map file " + f.map);
  }
  return f;
}

}  // namespace

std::optional<std::size_t> FloorsFile::find(const std::string& name) const {
  for (std::size_t i = 0; i < floors.size(); ++i) {
    if (floors[i].name == name) return i;
  }
  return std::nullopt;
}

std::string FloorsFile::names() const {
  std::string out;
  for (const Floor& f : floors) out += (out.empty() ? "" : ", ") + f.name;
  return out;
}

bool isFloorsFile(const std::string& path) {
  try {
    const YAML::Node doc = YAML::LoadFile(path);
    return doc.IsMap() && doc["floors"];
  } catch (const YAML::Exception&) {
    return false;
  }
}

FloorsFile loadFloorsFile(const std::string& path) {
  YAML::Node doc;
  try {
    doc = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw FloorsFileError(path + ": cannot be read");
  } catch (const YAML::Exception& e) {
    throw FloorsFileError(path + ": not YAML: " + e.what());
  }
  if (!doc.IsMap() || !doc["floors"] || !doc["floors"].IsSequence() || doc["floors"].size() == 0) {
    throw FloorsFileError(path + ": needs 'floors', a list of floors each with 'name' and 'map'");
  }
  FloorsFile out;
  out.file = path;
  const fs::path folder = fs::path(path).parent_path();
  const YAML::Node floors = doc["floors"];
  for (std::size_t i = 0; i < floors.size(); ++i) {
    const std::string where = path + ": floor " + std::to_string(i + 1);
    Floor f = readFloor(floors[i], folder, where);
    if (out.find(f.name)) throw FloorsFileError(where + ": a second floor named '" + f.name + "'");
    out.floors.push_back(std::move(f));
  }
  if (const YAML::Node initial = doc["initial_floor"]) {
    const auto index = initial.IsScalar() ? out.find(initial.Scalar()) : std::nullopt;
    if (!index) {
      throw FloorsFileError(path + ": initial_floor must name a floor (" + out.names() + ")");
    }
    out.initial = *index;
  }
  return out;
}

}  // namespace pf
