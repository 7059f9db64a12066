#include "pf_localization/core/map/map_loader.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

namespace pf {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------
// YAML metadata
// ---------------------------------------------------------------------------

// How a node looked in the file, for "got ..." in error messages.
std::string describe(const YAML::Node& node) {
  switch (node.Type()) {
    case YAML::NodeType::Undefined:
    case YAML::NodeType::Null:
      return "nothing";
    case YAML::NodeType::Scalar:
      return node.Scalar();
    case YAML::NodeType::Sequence: {
      std::string s = "[";
      for (std::size_t i = 0; i < node.size(); ++i) {
        if (i > 0) s += ", ";
        s += describe(node[i]);
      }
      return s + "]";
    }
    case YAML::NodeType::Map:
      return "a mapping";
  }
  return "?";
}

// Shortest text that reads back as the same double, so saved maps round-trip
// exactly and error messages do not show 0.65 as 0.650000.
std::string formatDouble(double v) {
  std::array<char, 32> buf;
  const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), v);
  return std::string(buf.data(), res.ptr);
}

class YamlFields {
 public:
  YamlFields(const std::string& file, const YAML::Node& doc) : file_(file), doc_(doc) {}

  [[noreturn]] void fail(const std::string& field, const std::string& problem) const {
    throw MapLoadError(file_ + ": field '" + field + "' " + problem);
  }

  // Null counts as absent: "negate:" with no value is a half-edited file, and
  // falling back to the default is what map_server's users expect.
  bool has(const char* field) const {
    const YAML::Node n = doc_[field];
    return n.IsDefined() && !n.IsNull();
  }

  YAML::Node required(const char* field) const {
    if (!has(field)) fail(field, "is missing (required)");
    return doc_[field];
  }

  // yaml-cpp accepts ".inf" and ".nan" as doubles; callers check finiteness
  // themselves because what is acceptable differs per field.
  static bool toDouble(const YAML::Node& n, double* out) {
    if (!n.IsScalar()) return false;
    try {
      *out = n.as<double>();
      return true;
    } catch (const YAML::BadConversion&) {
      return false;
    }
  }

  double threshold(const char* field, double fallback) const {
    if (!has(field)) return fallback;
    const YAML::Node n = doc_[field];
    double v = 0.0;
    if (!toDouble(n, &v) || !(v >= 0.0 && v <= 1.0)) {
      fail(field, "must be a number in [0, 1], got " + describe(n));
    }
    return v;
  }

 private:
  const std::string& file_;
  YAML::Node doc_;
};

MapMode parseMode(const YamlFields& fields, const YAML::Node& n) {
  if (n.IsScalar()) {
    const std::string& s = n.Scalar();
    if (s == "trinary") return MapMode::kTrinary;
    if (s == "scale") return MapMode::kScale;
    if (s == "raw") return MapMode::kRaw;
  }
  fields.fail("mode", "must be trinary, scale or raw, got '" + describe(n) + "'");
}

// map_server reads negate as an int; hand-written files also say true/false.
bool parseNegate(const YamlFields& fields, const YAML::Node& n) {
  if (n.IsScalar()) {
    try {
      const int i = n.as<int>();
      if (i == 0 || i == 1) return i == 1;
    } catch (const YAML::BadConversion&) {
      try {
        return n.as<bool>();
      } catch (const YAML::BadConversion&) {
      }
    }
  }
  fields.fail("negate", "must be 0, 1, true or false, got " + describe(n));
}

// ---------------------------------------------------------------------------
// Netpbm images
// ---------------------------------------------------------------------------

// A decoded image: per pixel, the sum of its channels after scaling each to
// 0..255, top row first (file order). Summing rather than averaging keeps the
// value an integer; the average is formed later exactly as map_server does.
struct RawImage {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<uint16_t> color_sum;
  // An 8-bit grey image's pixels, in the file's bytes, in place of color_sum.
  const unsigned char* gray = nullptr;
};

class PnmParser {
 public:
  PnmParser(const std::string& path, const std::string& bytes) : path_(path), buf_(bytes) {}

  RawImage parse() {
    const std::string magic = buf_.substr(0, 2);
    const bool ascii = magic == "P2" || magic == "P3";
    const int channels = magic == "P3" || magic == "P6" ? 3 : 1;
    const bool separated =
        buf_.size() > 2 && (std::isspace(static_cast<unsigned char>(buf_[2])) || buf_[2] == '#');
    if (!separated || (magic != "P2" && magic != "P3" && magic != "P5" && magic != "P6")) {
      if (buf_.compare(0, 4, "\x89PNG") == 0) {
        fail("PNG images are not supported; convert it to PGM (e.g. 'convert map.png map.pgm')");
      }
      fail("unsupported image format (magic number '" + printable(magic) +
           "'); expected PGM (P2, P5) or PPM (P3, P6)");
    }
    pos_ = 2;
    const uint64_t w = headerNumber("width");
    const uint64_t h = headerNumber("height");
    const uint64_t maxval = headerNumber("maxval");
    if (w == 0 || h == 0) {
      fail("image has no pixels (" + std::to_string(w) + " x " + std::to_string(h) + ")");
    }
    // OccupancyGrid indexes cells with int.
    if (w * h > static_cast<uint64_t>(INT_MAX)) {
      fail("image is too large (" + std::to_string(w) + " x " + std::to_string(h) + ")");
    }
    if (maxval == 0 || maxval > 65535) {
      fail("maxval must be in 1..65535, got " + std::to_string(maxval));
    }

    RawImage img;
    img.width = static_cast<int>(w);
    img.height = static_cast<int>(h);
    img.channels = channels;
    maxval_ = static_cast<uint32_t>(maxval);
    const uint64_t samples = w * h * channels;

    // The pixel buffer is allocated only once the file is known to be long
    // enough, so a corrupt header cannot ask for gigabytes.
    if (ascii) {
      // Every sample takes at least one byte; if they cannot all be there the
      // loop still runs, to report how many were found.
      if (buf_.size() - pos_ >= samples) img.color_sum.assign(w * h, 0);
      for (uint64_t i = 0; i < samples; ++i) {
        const uint16_t v = scale(asciiSample(i, samples, img), i);
        if (!img.color_sum.empty()) img.color_sum[i / channels] += v;
      }
    } else {
      // Exactly one whitespace byte separates maxval from the raster, which
      // may itself start with a byte that looks like whitespace.
      if (pos_ >= buf_.size() || !std::isspace(static_cast<unsigned char>(buf_[pos_]))) {
        fail("expected a single whitespace after maxval in the header");
      }
      ++pos_;
      const uint64_t bytes_per_sample = maxval > 255 ? 2 : 1;
      const uint64_t needed = samples * bytes_per_sample;
      const uint64_t available = buf_.size() - pos_;
      if (available < needed) {
        const uint64_t row_bytes = w * channels * bytes_per_sample;
        fail("truncated pixel data: a " + std::to_string(w) + " x " + std::to_string(h) + " " +
             magic + " image with maxval " + std::to_string(maxval) + " needs " +
             std::to_string(needed) + " bytes after the header, found " +
             std::to_string(available) + " (only " + std::to_string(available / row_bytes) +
             " of " + std::to_string(h) + " rows complete)");
      }
      const auto* p = reinterpret_cast<const unsigned char*>(buf_.data()) + pos_;
      if (bytes_per_sample == 1 && channels == 1 && maxval == 255) {
        // What map_saver writes: each byte is its own sum, and none can
        // exceed maxval; read where it lies.
        img.gray = p;
        return img;
      }
      img.color_sum.assign(w * h, 0);
      for (uint64_t i = 0; i < samples; ++i) {
        // Netpbm stores 16-bit samples most significant byte first.
        const uint64_t v = bytes_per_sample == 2 ? (uint64_t{p[2 * i]} << 8) | p[2 * i + 1] : p[i];
        img.color_sum[i / channels] += scale(v, i);
      }
    }
    return img;
  }

 private:
  [[noreturn]] void fail(const std::string& problem) const {
    throw MapLoadError(path_ + ": " + problem);
  }

  static std::string printable(const std::string& s) {
    std::string out;
    for (const char c : s) {
      const auto u = static_cast<unsigned char>(c);
      if (std::isprint(u)) {
        out += c;
      } else {
        char hex[8];
        std::snprintf(hex, sizeof(hex), "\\x%02x", u);
        out += hex;
      }
    }
    return out;
  }

  // Comments run from '#' to the end of the line and may sit between any two
  // header tokens (GIMP and map_saver both write one after the magic number).
  void skipSpaceAndComments() {
    while (pos_ < buf_.size()) {
      const char c = buf_[pos_];
      if (c == '#') {
        while (pos_ < buf_.size() && buf_[pos_] != '\n') ++pos_;
      } else if (std::isspace(static_cast<unsigned char>(c))) {
        ++pos_;
      } else {
        break;
      }
    }
  }

  // Digits at pos_; the caps keep the arithmetic below overflow-free.
  bool readNumber(uint64_t* out) {
    if (pos_ >= buf_.size() || !std::isdigit(static_cast<unsigned char>(buf_[pos_]))) {
      return false;
    }
    uint64_t v = 0;
    while (pos_ < buf_.size() && std::isdigit(static_cast<unsigned char>(buf_[pos_]))) {
      v = std::min<uint64_t>(v * 10 + (buf_[pos_] - '0'), uint64_t{1} << 40);
      ++pos_;
    }
    *out = v;
    return true;
  }

  uint64_t headerNumber(const char* what) {
    skipSpaceAndComments();
    if (pos_ >= buf_.size()) fail(std::string("header ends before the ") + what);
    uint64_t v = 0;
    if (!readNumber(&v)) {
      fail(std::string("expected the ") + what + " in the header at byte " + std::to_string(pos_) +
           ", found '" + printable(buf_.substr(pos_, 1)) + "'");
    }
    return v;
  }

  uint64_t asciiSample(uint64_t index, uint64_t samples, const RawImage& img) {
    skipSpaceAndComments();
    if (pos_ >= buf_.size()) {
      const uint64_t row_samples = static_cast<uint64_t>(img.width) * img.channels;
      fail("truncated pixel data: expected " + std::to_string(samples) + " samples for " +
           std::to_string(img.width) + " x " + std::to_string(img.height) + " pixels, found " +
           std::to_string(index) + " (only " + std::to_string(index / row_samples) + " of " +
           std::to_string(img.height) + " rows complete)");
    }
    uint64_t v = 0;
    if (!readNumber(&v)) {
      fail("unexpected '" + printable(buf_.substr(pos_, 1)) + "' in the pixel data at byte " +
           std::to_string(pos_));
    }
    return v;
  }

  // A sample above maxval has no meaning; clamping would hide a broken file.
  // Sub-8-bit and 16-bit samples are rescaled to 0..255 with rounding.
  uint16_t scale(uint64_t v, uint64_t index) const {
    if (v > maxval_) {
      fail("sample " + std::to_string(index) + " is " + std::to_string(v) + ", above maxval " +
           std::to_string(maxval_));
    }
    if (maxval_ == 255) return static_cast<uint16_t>(v);
    return static_cast<uint16_t>((v * 255 + maxval_ / 2) / maxval_);
  }

  const std::string& path_;
  const std::string& buf_;
  std::size_t pos_ = 0;
  uint32_t maxval_ = 255;
};

// The cell value map_server (ROS 1 Noetic, image_loader.cpp) gives a pixel
// whose channels, each 0..255, add up to color_sum. The floating-point steps
// are kept in map_server's order so thresholds compare identically.
//
// map_server treats the last channel of a multi-channel pixel as alpha in
// scale mode, which for an RGB image without alpha is really a colour channel
// (a pixel with that channel at 0 becomes unknown). PPM has no alpha, so we
// deliberately do not reproduce that.
int8_t cellValue(int color_sum, int channels, const MapMetadata& meta) {
  double color_avg = color_sum / static_cast<double>(channels);
  if (meta.negate) color_avg = 255 - color_avg;
  // map_server assigns the double to an unsigned char (truncating) and that
  // to the int8 message field, so raw values above 127 wrap to negatives.
  if (meta.mode == MapMode::kRaw) return static_cast<int8_t>(static_cast<uint8_t>(color_avg));
  const double occ = (255 - color_avg) / 255.0;
  if (occ > meta.occupied_thresh) return 100;
  if (occ < meta.free_thresh) return 0;
  if (meta.mode == MapMode::kTrinary) return -1;
  const double ratio = (occ - meta.free_thresh) / (meta.occupied_thresh - meta.free_thresh);
  return static_cast<int8_t>(1 + 98 * ratio);  // in 1..99, truncated like map_server
}

std::string readFile(const std::string& path, const char* what) {
  // A directory opens as a stream on Linux and then throws on the first read.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    throw MapLoadError(path + ": the " + std::string(what) + " is a directory, not a file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    throw MapLoadError(path + ": cannot open " + what + " (" + std::strerror(errno) + ")");
  }
  try {
    // In blocks, not a character at a time: a large map's image is tens of MB.
    std::string bytes;
    std::error_code size_error;
    const auto size = std::filesystem::file_size(path, size_error);
    if (!size_error) bytes.reserve(size);
    char block[1 << 16];
    while (in.read(block, sizeof block) || in.gcount() > 0) bytes.append(block, in.gcount());
    if (in.bad()) throw MapLoadError(path + ": error while reading " + what);
    return bytes;
  } catch (const std::ios_base::failure& e) {
    throw MapLoadError(path + ": error while reading " + what + " (" + e.what() + ")");
  }
}

// Plain when that is unambiguous (as map_saver writes it), else double-quoted.
std::string yamlString(const std::string& s) {
  bool plain = !s.empty();
  for (const char c : s) {
    plain = plain && (std::isalnum(static_cast<unsigned char>(c)) || std::strchr("._-/+", c));
  }
  if (plain) return s;
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out + "\"";
}

void writeFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) {
    throw std::runtime_error(path + ": cannot write (" + std::strerror(errno) + ")");
  }
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) throw std::runtime_error(path + ": error while writing");
}

}  // namespace

MapMetadata loadMapMetadata(const std::string& yaml_path) {
  const std::string text = readFile(yaml_path, "map file");
  YAML::Node doc;
  try {
    doc = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw MapLoadError(yaml_path + ": not valid YAML: " + e.msg + " (line " +
                       std::to_string(e.mark.line + 1) + ", column " +
                       std::to_string(e.mark.column + 1) + ")");
  }
  if (!doc.IsMap()) {
    throw MapLoadError(yaml_path +
                       ": not a map_server YAML file (expected fields such as 'image: map.pgm')");
  }
  const YamlFields fields(yaml_path, doc);
  MapMetadata meta;

  const YAML::Node image = fields.required("image");
  if (!image.IsScalar() || image.Scalar().empty()) {
    fields.fail("image", "must be an image file name, got " + describe(image));
  }
  // As map_server: relative to the YAML's folder, not the working directory,
  // so a map folder can be moved as a whole.
  const fs::path image_path(image.Scalar());
  meta.image = image_path.is_absolute() ? image_path.string()
                                        : (fs::path(yaml_path).parent_path() / image_path).string();

  const YAML::Node res = fields.required("resolution");
  if (!YamlFields::toDouble(res, &meta.resolution) || !std::isfinite(meta.resolution) ||
      meta.resolution <= 0.0) {
    fields.fail("resolution", "must be a positive number, got " + describe(res));
  }

  const YAML::Node origin = fields.required("origin");
  std::array<double, 3> o{};
  bool origin_ok = origin.IsSequence() && origin.size() == 3;
  for (std::size_t i = 0; origin_ok && i < 3; ++i) {
    origin_ok = YamlFields::toDouble(origin[i], &o[i]) && std::isfinite(o[i]);
  }
  if (!origin_ok) {
    fields.fail("origin",
                "must be a list of 3 finite numbers [x, y, yaw], got " + describe(origin));
  }
  meta.origin = {o[0], o[1], normalizeAngle(o[2])};

  if (fields.has("negate")) meta.negate = parseNegate(fields, doc["negate"]);
  meta.occupied_thresh = fields.threshold("occupied_thresh", meta.occupied_thresh);
  meta.free_thresh = fields.threshold("free_thresh", meta.free_thresh);
  // Equal thresholds would leave scale mode dividing by zero.
  if (!(meta.free_thresh < meta.occupied_thresh)) {
    fields.fail("free_thresh", "(" + formatDouble(meta.free_thresh) +
                                   ") must be below 'occupied_thresh' (" +
                                   formatDouble(meta.occupied_thresh) + ")");
  }
  if (fields.has("mode")) meta.mode = parseMode(fields, doc["mode"]);
  return meta;
}

OccupancyGrid loadMapImage(const MapMetadata& meta) {
  if (!(meta.free_thresh >= 0.0 && meta.free_thresh < meta.occupied_thresh &&
        meta.occupied_thresh <= 1.0)) {
    throw MapLoadError(meta.image + ": thresholds must satisfy 0 <= free_thresh (" +
                       formatDouble(meta.free_thresh) + ") < occupied_thresh (" +
                       formatDouble(meta.occupied_thresh) + ") <= 1");
  }
  const std::string bytes = readFile(meta.image, "image file");
  const RawImage img = PnmParser(meta.image, bytes).parse();

  // Only 3 * 255 + 1 distinct sums exist: convert each once.
  std::vector<int8_t> lut(255 * img.channels + 1);
  for (int s = 0; s < static_cast<int>(lut.size()); ++s) lut[s] = cellValue(s, img.channels, meta);

  // Image rows run top to bottom, grid rows bottom to top.
  const std::size_t w = img.width;
  std::vector<int8_t> data(w * img.height);
  for (std::size_t row = 0; row < static_cast<std::size_t>(img.height); ++row) {
    const std::size_t src = (img.height - 1 - row) * w;
    int8_t* out = &data[row * w];
    if (img.gray) {
      for (std::size_t col = 0; col < w; ++col) out[col] = lut[img.gray[src + col]];
    } else {
      for (std::size_t col = 0; col < w; ++col) out[col] = lut[img.color_sum[src + col]];
    }
  }
  try {
    return OccupancyGrid(img.width, img.height, meta.resolution, meta.origin, std::move(data));
  } catch (const std::invalid_argument& e) {
    throw MapLoadError(meta.image + ": " + e.what());
  }
}

OccupancyGrid loadMap(const std::string& yaml_path) {
  const MapMetadata meta = loadMapMetadata(yaml_path);
  try {
    return loadMapImage(meta);
  } catch (const MapLoadError& e) {
    // The image's own message names the image; the user edits the YAML.
    throw MapLoadError(yaml_path + ": field 'image': " + e.what());
  }
}

void saveMap(const OccupancyGrid& grid, const std::string& yaml_path) {
  std::vector<std::uint8_t> pixels(grid.data().size());
  for (int y = 0; y < grid.height(); ++y) {
    for (int x = 0; x < grid.width(); ++x) {
      // The grid's own classification, so the saved map shows the filter's view.
      std::uint8_t& p = pixels[static_cast<std::size_t>(grid.linearIndex({x, y}))];
      switch (grid.state({x, y})) {
        case CellState::kOccupied:
          p = 0;
          break;
        case CellState::kFree:
          p = 254;
          break;
        case CellState::kUnknown:
          p = 205;
          break;
      }
    }
  }
  saveImage(grid, pixels, yaml_path);
}

void saveImage(const OccupancyGrid& grid, const std::vector<std::uint8_t>& pixels,
               const std::string& yaml_path) {
  if (grid.empty()) throw std::invalid_argument("saveMap: the grid is empty");
  if (pixels.size() != grid.data().size()) {
    throw std::invalid_argument("saveImage: " + std::to_string(pixels.size()) +
                                " pixels for a grid of " + std::to_string(grid.data().size()) +
                                " cells");
  }
  fs::path image_path(yaml_path);
  image_path.replace_extension(".pgm");
  if (image_path == fs::path(yaml_path)) {
    throw std::invalid_argument("saveMap: " + yaml_path + " would be overwritten by its own image");
  }

  const int w = grid.width(), h = grid.height();
  std::string pgm = "P5\n# CREATOR: pf_localization saveMap " + formatDouble(grid.resolution()) +
                    " m/pix\n" + std::to_string(w) + " " + std::to_string(h) + "\n255\n";
  const std::size_t header = pgm.size();
  pgm.resize(header + static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    // The image's first row is the map's top row.
    std::copy_n(pixels.begin() + static_cast<std::ptrdiff_t>(y) * w, w,
                pgm.begin() +
                    static_cast<std::ptrdiff_t>(header + static_cast<std::size_t>(h - 1 - y) * w));
  }
  writeFile(image_path.string(), pgm);

  const Pose2& o = grid.origin();
  // The image is named relative to the YAML so the pair can be moved together.
  std::ostringstream yaml;
  yaml << "image: " << yamlString(image_path.filename().string()) << "\n"
       << "resolution: " << formatDouble(grid.resolution()) << "\n"
       << "origin: [" << formatDouble(o.x) << ", " << formatDouble(o.y) << ", "
       << formatDouble(o.yaw) << "]\n"
       << "negate: 0\n"
       << "occupied_thresh: 0.65\n"
       << "free_thresh: 0.196\n"
       << "mode: trinary\n";
  writeFile(yaml_path, yaml.str());
}

}  // namespace pf
