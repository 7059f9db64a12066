// libFuzzer target: arbitrary bytes written as a map_server YAML file or as a
// PGM/PPM image into a private temporary folder, then pf::loadMap /
// pf::loadMapMetadata / pf::loadMapImage. A malformed file must end in
// MapLoadError (with a message naming the file); anything else - a crash, a
// sanitizer report, another exception, a grid that disagrees with itself - is
// a finding.
//
// Input layout: selector u8, then
//   selector % 2 == 0 (image): mode u8 (bits0-1 trinary/scale/raw, bit2
//     negate, bit3 odd thresholds: two more u8), the rest is the image file;
//     it is loaded through a fixed YAML with loadMap and directly with
//     loadMapImage.
//   selector % 2 == 1 (YAML): the rest is the YAML file; a valid 3 x 2 P5
//     image "map.pgm" sits beside it.
#include <unistd.h>

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "fuzz_input.h"
#include "pf_localization/core/map/map_loader.h"

namespace {

namespace fs = std::filesystem;

const std::string& tempDir() {
  static const std::string dir = [] {
    char templ[] = "/tmp/pf_fuzz_map_XXXXXX";
    const char* d = mkdtemp(templ);
    if (!d) std::abort();
    return std::string(d);
  }();
  return dir;
}

void writeFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

void checkGrid(const pf::OccupancyGrid& g) {
  PF_FUZZ_CHECK(g.width() > 0 && g.height() > 0, "%d x %d grid", g.width(), g.height());
  PF_FUZZ_CHECK(g.data().size() == static_cast<std::size_t>(g.width()) * g.height(),
                "%zu cells for %d x %d", g.data().size(), g.width(), g.height());
  PF_FUZZ_CHECK(std::isfinite(g.resolution()) && g.resolution() > 0.0, "resolution %g",
                g.resolution());
  PF_FUZZ_CHECK(g.origin().isFinite(), "non-finite origin");
}

void checkError(const pf::MapLoadError& e, const std::string& file) {
  PF_FUZZ_CHECK(std::strlen(e.what()) > 0, "empty MapLoadError");
  PF_FUZZ_CHECK(std::string(e.what()).find(file) != std::string::npos,
                "MapLoadError does not name %s: %s", file.c_str(), e.what());
}

// A YAML file may name any path as its image; only files in our folder (or
// missing ones) are read, so /dev/zero or a FIFO cannot hang the fuzzer.
bool safeImage(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || st.type() == fs::file_type::not_found) return true;
  if (st.type() != fs::file_type::regular && st.type() != fs::file_type::directory) return false;
  const std::string canon = fs::weakly_canonical(path, ec).string();
  return !ec && canon.rfind(tempDir(), 0) == 0;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, std::size_t size) {
  pf_fuzz::Input in(data, size);
  const std::string dir = tempDir();
  const std::string yaml = dir + "/map.yaml";
  const std::string image = dir + "/map.pgm";
  const uint8_t selector = in.u8();

  if (selector % 2 == 0) {
    const uint8_t mode = in.u8();
    pf::MapMetadata meta;
    meta.image = image;
    meta.resolution = 0.05;
    meta.origin = {-1.0, 2.0, 0.5};
    meta.negate = mode & 4;
    meta.mode = (mode & 3) == 1   ? pf::MapMode::kScale
                : (mode & 3) == 2 ? pf::MapMode::kRaw
                                  : pf::MapMode::kTrinary;
    if (mode & 8) {
      meta.free_thresh = in.u8() / 200.0;  // may be above 1 or above occupied_thresh
      meta.occupied_thresh = in.u8() / 200.0;
    }
    writeFile(image, in.rest());
    static const char* const kModes[] = {"trinary", "scale", "raw"};
    writeFile(yaml, "image: map.pgm\nresolution: 0.05\norigin: [-1.0, 2.0, 0.5]\nnegate: " +
                        std::to_string(meta.negate ? 1 : 0) +
                        "\noccupied_thresh: " + std::to_string(meta.occupied_thresh) +
                        "\nfree_thresh: " + std::to_string(meta.free_thresh) + "\nmode: " +
                        kModes[meta.mode == pf::MapMode::kScale ? 1
                               : meta.mode == pf::MapMode::kRaw ? 2
                                                                : 0] +
                        "\n");
    try {
      checkGrid(pf::loadMapImage(meta));
    } catch (const pf::MapLoadError& e) {
      checkError(e, image);
    }
    try {
      checkGrid(pf::loadMap(yaml));
    } catch (const pf::MapLoadError& e) {
      checkError(e, yaml);
    }
    return 0;
  }

  // A YAML file with a valid image beside it.
  writeFile(image, std::string("P5\n3 2\n255\n") + std::string("\x00\xfe\xcd\xfe\x00\x80", 6));
  writeFile(yaml, in.rest());
  pf::MapMetadata meta;
  try {
    meta = pf::loadMapMetadata(yaml);
  } catch (const pf::MapLoadError& e) {
    checkError(e, yaml);
    return 0;
  }
  PF_FUZZ_CHECK(std::isfinite(meta.resolution) && meta.resolution > 0.0, "resolution %g",
                meta.resolution);
  PF_FUZZ_CHECK(meta.origin.isFinite(), "non-finite origin");
  PF_FUZZ_CHECK(meta.free_thresh >= 0.0 && meta.free_thresh < meta.occupied_thresh &&
                    meta.occupied_thresh <= 1.0,
                "thresholds %g %g", meta.free_thresh, meta.occupied_thresh);
  if (!safeImage(meta.image)) return 0;
  try {
    checkGrid(pf::loadMap(yaml));
  } catch (const pf::MapLoadError& e) {
    checkError(e, yaml);
  }
  return 0;
}
