// A MapChangeLayer's learned state framed as a file, to be restored after a
// restart on the same map only: a header naming the format and its version
// and the signature of the map it was learned on (the caller's text: the
// ROS side gives its mapSignature), the state (MapChangeLayer::encode()),
// and a 64-bit FNV-1a checksum of the state, so that a file cut short or
// altered is refused before any of it is read. Unseen cells cost nothing:
// the cells' states are run-length coded, and only the cells with counts
// list them (a map of 4 million cells with 8 900 seen: 5.4 kB). See
// docs/ros-interface.md, "The map's changes across a restart".
#pragma once

#include <string>

#include "pf_localization/core/map/map_change_layer.h"

namespace pf {

/// The version mapChangesFile() writes and readMapChangesFile() reads.
constexpr int kMapChangesFileVersion = 2;

/// `layer`'s state as a file's bytes, learned on the map `map_signature` names.
std::string mapChangesFile(const MapChangeLayer& layer, const std::string& map_signature);

/// A file's bytes read back, without the layer: what it says it is.
struct MapChangesFileContents {
  std::string
      error;  // empty: read; else why not (not such a file, another version, cut short, corrupt)
  std::string map_signature;  // the map it was learned on
  std::string state;          // for MapChangeLayer::decode()
};
MapChangesFileContents readMapChangesFile(const std::string& bytes);

}  // namespace pf
