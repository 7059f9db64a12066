#include "pf_localization/core/map/map_loader.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace pf {
namespace {

namespace fs = std::filesystem;

// Each test writes its files into its own fresh folder, so tests can run in
// any order (or in parallel via gtest sharding) without seeing each other's maps.
class MapLoaderTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / "pf_map_loader_test" / info->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }

  // Returns the file's full path.
  std::string write(const std::string& name, const std::string& bytes) {
    const fs::path p = dir_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << bytes;
    return p.string();
  }

  // A map YAML for `image` with map_server's usual fields plus `extra` lines.
  std::string writeYaml(const std::string& name, const std::string& image,
                        const std::string& extra = "") {
    return write(name, "image: " + image + "\nresolution: 0.5\norigin: [1.5, -2.0, 0.0]\n" + extra);
  }

  // The MapLoadError message of loadMap(yaml), or a test failure.
  static std::string loadError(const std::string& yaml) {
    try {
      loadMap(yaml);
    } catch (const MapLoadError& e) {
      return e.what();
    }
    ADD_FAILURE() << "loadMap(" << yaml << ") did not throw";
    return "";
  }

  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

std::string readAll(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

using Cells = std::vector<int8_t>;

// --- Metadata ----------------------------------------------------------------

TEST_F(MapLoaderTest, MetadataDefaultsAreMapServers) {
  write("m.pgm", "P2 1 1 255 0\n");
  const MapMetadata meta = loadMapMetadata(writeYaml("m.yaml", "m.pgm"));
  EXPECT_EQ(meta.image, path("m.pgm"));
  EXPECT_EQ(meta.resolution, 0.5);
  EXPECT_EQ(meta.origin.x, 1.5);
  EXPECT_EQ(meta.origin.y, -2.0);
  EXPECT_EQ(meta.origin.yaw, 0.0);
  EXPECT_FALSE(meta.negate);
  EXPECT_EQ(meta.occupied_thresh, 0.65);
  EXPECT_EQ(meta.free_thresh, 0.196);
  EXPECT_EQ(meta.mode, MapMode::kTrinary);
}

TEST_F(MapLoaderTest, MetadataReadsEveryField) {
  const MapMetadata meta =
      loadMapMetadata(write("m.yaml",
                            "image: m.pgm\nresolution: 0.05\norigin: [-3, 4.25, 0.5]\nnegate: 1\n"
                            "occupied_thresh: 0.7\nfree_thresh: 0.1\nmode: scale\n"));
  EXPECT_EQ(meta.resolution, 0.05);
  EXPECT_EQ(meta.origin.x, -3.0);
  EXPECT_EQ(meta.origin.y, 4.25);
  EXPECT_EQ(meta.origin.yaw, 0.5);
  EXPECT_TRUE(meta.negate);
  EXPECT_EQ(meta.occupied_thresh, 0.7);
  EXPECT_EQ(meta.free_thresh, 0.1);
  EXPECT_EQ(meta.mode, MapMode::kScale);
  EXPECT_EQ(loadMapMetadata(writeYaml("raw.yaml", "m.pgm", "mode: raw\n")).mode, MapMode::kRaw);
  EXPECT_TRUE(loadMapMetadata(writeYaml("t.yaml", "m.pgm", "negate: true\n")).negate);
  EXPECT_FALSE(loadMapMetadata(writeYaml("f.yaml", "m.pgm", "negate: false\n")).negate);
}

TEST_F(MapLoaderTest, OriginYawIsWrappedIntoPlusMinusPi) {
  const MapMetadata meta =
      loadMapMetadata(write("m.yaml", "image: m.pgm\nresolution: 1\norigin: [0, 0, 4.0]\n"));
  EXPECT_DOUBLE_EQ(meta.origin.yaw, 4.0 - 2.0 * M_PI);
}

TEST_F(MapLoaderTest, RelativeImagePathIsTakenFromTheYamlsFolder) {
  write("maps/img/m.pgm", "P2 1 1 255 0\n");
  const std::string yaml = writeYaml("maps/m.yaml", "img/m.pgm");
  EXPECT_EQ(loadMapMetadata(yaml).image, path("maps/img/m.pgm"));
  EXPECT_EQ(loadMap(yaml).data(), Cells({100}));
}

TEST_F(MapLoaderTest, AbsoluteImagePathIsKept) {
  const std::string image = write("elsewhere/m.pgm", "P2 1 1 255 255\n");
  const std::string yaml = writeYaml("maps/m.yaml", image);
  EXPECT_EQ(loadMapMetadata(yaml).image, image);
  EXPECT_EQ(loadMap(yaml).data(), Cells({0}));
}

// --- Pixel values --------------------------------------------------------------

TEST_F(MapLoaderTest, TrinaryP2FlipsRowsSoTheTopRowIsTheLastGridRow) {
  write("m.pgm",
        "P2\n# a comment\n2 3\n255\n"
        "0 255\n"     // top
        "205 254\n"   // middle: 205 is map_saver's unknown, just above free_thresh
        "10 250\n");  // bottom
  const OccupancyGrid g = loadMap(writeYaml("m.yaml", "m.pgm"));
  EXPECT_EQ(g.width(), 2);
  EXPECT_EQ(g.height(), 3);
  EXPECT_EQ(g.resolution(), 0.5);
  EXPECT_EQ(g.origin().x, 1.5);
  EXPECT_EQ(g.origin().y, -2.0);
  EXPECT_EQ(g.data(), Cells({100, 0, -1, 0, 100, 0}));
}

TEST_F(MapLoaderTest, TrinaryThresholdsAreStrict) {
  // 51 gives p = 0.8 and 204 gives p = 0.2 exactly: neither is beyond its threshold.
  write("m.pgm", "P2 4 1 255 50 51 204 205\n");
  const OccupancyGrid g =
      loadMap(writeYaml("m.yaml", "m.pgm", "occupied_thresh: 0.8\nfree_thresh: 0.2\n"));
  EXPECT_EQ(g.data(), Cells({100, -1, -1, 0}));
}

TEST_F(MapLoaderTest, NegateSwapsBlackAndWhite) {
  write("m.pgm", "P2 4 1 255 0 255 205 50\n");
  const Cells expected = {0, 100, 100, -1};
  EXPECT_EQ(loadMap(writeYaml("n1.yaml", "m.pgm", "negate: 1\n")).data(), expected);
  EXPECT_EQ(loadMap(writeYaml("nt.yaml", "m.pgm", "negate: true\n")).data(), expected);
}

TEST_F(MapLoaderTest, ScaleModeInterpolatesBetweenTheThresholds) {
  // Between the thresholds: (int)(1 + 98 * (p - 0.196) / (0.65 - 0.196)).
  write("m.pgm", "P2 7 1 255 0 128 150 200 205 206 255\n");
  EXPECT_EQ(loadMap(writeYaml("m.yaml", "m.pgm", "mode: scale\n")).data(),
            Cells({100, 66, 47, 5, 1, 0, 0}));
}

TEST_F(MapLoaderTest, ScaleModeWithNegate) {
  write("m.pgm", "P2 3 1 255 127 255 0\n");
  EXPECT_EQ(loadMap(writeYaml("m.yaml", "m.pgm", "mode: scale\nnegate: 1\n")).data(),
            Cells({66, 100, 0}));
}

TEST_F(MapLoaderTest, RawModeKeepsThePixelValueWrappedToInt8) {
  write("m.pgm", "P2 4 1 255 0 100 200 255\n");
  EXPECT_EQ(loadMap(writeYaml("m.yaml", "m.pgm", "mode: raw\n")).data(), Cells({0, 100, -56, -1}));
  EXPECT_EQ(loadMap(writeYaml("n.yaml", "m.pgm", "mode: raw\nnegate: 1\n")).data(),
            Cells({-1, -101, 55, 0}));
}

TEST_F(MapLoaderTest, BinaryP5) {
  // The first pixel byte is 10, a newline: only one whitespace ends the header.
  write("m.pgm",
        std::string("P5\n3 2\n255\n") + std::string({10, '\xff', '\xcd', '\xfe', 0, '\x80'}));
  EXPECT_EQ(loadMap(writeYaml("m.yaml", "m.pgm")).data(), Cells({0, 100, -1, 100, 0, -1}));
}

TEST_F(MapLoaderTest, BinaryP6AveragesTheChannels) {
  // Averages 85 (occupied), 210 (free), 170 (unknown).
  write("m.ppm", std::string("P6 3 1 255\n") +
                     std::string({'\xff', 0, 0, '\xc8', '\xd2', '\xdc', '\xff', '\xff', 0}));
  EXPECT_EQ(loadMap(writeYaml("m.yaml", "m.ppm")).data(), Cells({100, 0, -1}));
}

TEST_F(MapLoaderTest, AsciiP3AveragesTheChannelsAndTruncatesInRawMode) {
  // Raw: the average 2/3 truncates to 0, 254.67 to 254 (-2 as int8).
  write("m.ppm",
        "P3\n# comment\n2 2\n# another\n255\n"
        "1 1 0  255 255 254\n"
        "255 0 0  200 210 220\n");
  EXPECT_EQ(loadMap(writeYaml("raw.yaml", "m.ppm", "mode: raw\n")).data(), Cells({85, -46, 0, -2}));
  EXPECT_EQ(loadMap(writeYaml("tri.yaml", "m.ppm")).data(), Cells({100, 0, 100, 0}));
}

TEST_F(MapLoaderTest, SixteenBitSamplesAreScaledTo8Bit) {
  // 65535 -> 255, 52685 = 205 * 257 -> 205, 32768 -> 128.0 rounded to 128.
  write("m.pgm", std::string("P5 4 1 65535\n") +
                     std::string({0, 0, '\xff', '\xff', '\xcd', '\xcd', '\x80', 0}));
  EXPECT_EQ(loadMap(writeYaml("raw.yaml", "m.pgm", "mode: raw\n")).data(),
            Cells({0, -1, -51, -128}));
  EXPECT_EQ(loadMap(writeYaml("tri.yaml", "m.pgm")).data(), Cells({100, 0, -1, -1}));
}

TEST_F(MapLoaderTest, SmallMaxvalIsScaledWithRounding) {
  // 7 * 255 / 15 = 119, 8 * 255 / 15 = 136 (-120 as int8).
  write("m.pgm", "P2 4 1 15 0 7 8 15\n");
  EXPECT_EQ(loadMap(writeYaml("m.yaml", "m.pgm", "mode: raw\n")).data(), Cells({0, 119, -120, -1}));
}

// --- Saving ------------------------------------------------------------------

TEST_F(MapLoaderTest, SaveWritesMapSaversTrinaryPgmAndYaml) {
  const OccupancyGrid g(3, 2, 0.05, {-1.5, 2.25, 0.3}, {100, 0, -1, -1, 0, 100});
  saveMap(g, path("out.yaml"));
  const std::string pgm = readAll(path("out.pgm"));
  const std::string header = "P5\n# CREATOR: pf_localization saveMap 0.05 m/pix\n3 2\n255\n";
  ASSERT_EQ(pgm.size(), header.size() + 6);
  EXPECT_EQ(pgm.substr(0, header.size()), header);
  // Top row first.
  EXPECT_EQ(pgm.substr(header.size()), std::string({'\xcd', '\xfe', 0, 0, '\xfe', '\xcd'}));
  EXPECT_EQ(readAll(path("out.yaml")),
            "image: out.pgm\nresolution: 0.05\norigin: [-1.5, 2.25, 0.3]\nnegate: 0\n"
            "occupied_thresh: 0.65\nfree_thresh: 0.196\nmode: trinary\n");
}

TEST_F(MapLoaderTest, SaveThenLoadGivesTheSameTrinaryGrid) {
  const OccupancyGrid g(3, 2, 0.05, {-1.5, 2.25, 0.3}, {100, 0, -1, -1, 0, 100});
  saveMap(g, path("rt.yaml"));
  const OccupancyGrid back = loadMap(path("rt.yaml"));
  EXPECT_EQ(back.width(), 3);
  EXPECT_EQ(back.height(), 2);
  EXPECT_EQ(back.resolution(), 0.05);
  EXPECT_EQ(back.origin().x, -1.5);
  EXPECT_EQ(back.origin().y, 2.25);
  EXPECT_EQ(back.origin().yaw, 0.3);
  EXPECT_EQ(back.data(), g.data());
}

TEST_F(MapLoaderTest, SaveClassifiesIntermediateValues) {
  // 10 is free, 50 unknown, 80 occupied by OccupancyGrid::classify.
  const OccupancyGrid g(3, 1, 1.0, {}, {10, 50, 80});
  saveMap(g, path("s.yaml"));
  EXPECT_EQ(loadMap(path("s.yaml")).data(), Cells({0, -1, 100}));
}

// --- Errors: each names the file and the field ---------------------------------

TEST_F(MapLoaderTest, MissingYamlFile) {
  EXPECT_EQ(loadError(path("nope.yaml")),
            path("nope.yaml") + ": cannot open map file (No such file or directory)");
}

TEST_F(MapLoaderTest, InvalidYaml) {
  const std::string yaml = write("m.yaml", "image: [m.pgm\n");
  const std::string msg = loadError(yaml);
  EXPECT_EQ(msg.rfind(yaml + ": not valid YAML: ", 0), 0u) << msg;
}

TEST_F(MapLoaderTest, MissingFields) {
  EXPECT_EQ(loadError(write("a.yaml", "resolution: 1\norigin: [0, 0, 0]\n")),
            path("a.yaml") + ": field 'image' is missing (required)");
  EXPECT_EQ(loadError(write("b.yaml", "image: m.pgm\norigin: [0, 0, 0]\n")),
            path("b.yaml") + ": field 'resolution' is missing (required)");
  EXPECT_EQ(loadError(write("c.yaml", "image: m.pgm\nresolution: 1\n")),
            path("c.yaml") + ": field 'origin' is missing (required)");
  EXPECT_EQ(
      loadError(write("d.yaml", "")),
      path("d.yaml") + ": not a map_server YAML file (expected fields such as 'image: map.pgm')");
}

TEST_F(MapLoaderTest, BadResolution) {
  const std::string base = "image: m.pgm\norigin: [0, 0, 0]\nresolution: ";
  EXPECT_EQ(loadError(write("a.yaml", base + "-1\n")),
            path("a.yaml") + ": field 'resolution' must be a positive number, got -1");
  EXPECT_EQ(loadError(write("b.yaml", base + "0\n")),
            path("b.yaml") + ": field 'resolution' must be a positive number, got 0");
  EXPECT_EQ(loadError(write("c.yaml", base + "fine\n")),
            path("c.yaml") + ": field 'resolution' must be a positive number, got fine");
  EXPECT_EQ(loadError(write("d.yaml", base + ".inf\n")),
            path("d.yaml") + ": field 'resolution' must be a positive number, got .inf");
}

TEST_F(MapLoaderTest, BadOrigin) {
  const std::string base = "image: m.pgm\nresolution: 1\norigin: ";
  EXPECT_EQ(loadError(write("a.yaml", base + "[1, 2]\n")),
            path("a.yaml") +
                ": field 'origin' must be a list of 3 finite numbers [x, y, yaw], got [1, 2]");
  EXPECT_EQ(loadError(write("b.yaml", base + "[1, x, 0]\n")),
            path("b.yaml") +
                ": field 'origin' must be a list of 3 finite numbers [x, y, yaw], got [1, x, 0]");
  EXPECT_EQ(
      loadError(write("c.yaml", base + "[1, .nan, 0]\n")),
      path("c.yaml") +
          ": field 'origin' must be a list of 3 finite numbers [x, y, yaw], got [1, .nan, 0]");
}

TEST_F(MapLoaderTest, BadThresholds) {
  EXPECT_EQ(loadError(writeYaml("a.yaml", "m.pgm", "occupied_thresh: 1.5\n")),
            path("a.yaml") + ": field 'occupied_thresh' must be a number in [0, 1], got 1.5");
  EXPECT_EQ(loadError(writeYaml("b.yaml", "m.pgm", "free_thresh: -0.1\n")),
            path("b.yaml") + ": field 'free_thresh' must be a number in [0, 1], got -0.1");
  EXPECT_EQ(loadError(writeYaml("c.yaml", "m.pgm", "free_thresh: 0.7\n")),
            path("c.yaml") + ": field 'free_thresh' (0.7) must be below 'occupied_thresh' (0.65)");
  EXPECT_EQ(loadError(writeYaml("d.yaml", "m.pgm", "free_thresh: 0.65\n")),
            path("d.yaml") + ": field 'free_thresh' (0.65) must be below 'occupied_thresh' (0.65)");
}

TEST_F(MapLoaderTest, BadModeAndNegate) {
  EXPECT_EQ(loadError(writeYaml("a.yaml", "m.pgm", "mode: fancy\n")),
            path("a.yaml") + ": field 'mode' must be trinary, scale or raw, got 'fancy'");
  EXPECT_EQ(loadError(writeYaml("b.yaml", "m.pgm", "negate: 2\n")),
            path("b.yaml") + ": field 'negate' must be 0, 1, true or false, got 2");
}

TEST_F(MapLoaderTest, MissingImageFile) {
  const std::string yaml = writeYaml("m.yaml", "gone.pgm");
  EXPECT_EQ(loadError(yaml), yaml + ": field 'image': " + path("gone.pgm") +
                                 ": cannot open image file (No such file or directory)");
}

TEST_F(MapLoaderTest, BadMagicNumber) {
  write("m.pgm", "P4\n1 1\n\x80");
  const std::string yaml = writeYaml("m.yaml", "m.pgm");
  EXPECT_EQ(loadError(yaml), yaml + ": field 'image': " + path("m.pgm") +
                                 ": unsupported image format (magic number 'P4'); expected "
                                 "PGM (P2, P5) or PPM (P3, P6)");
  write("p.png", "\x89PNG\r\n\x1a\n");
  const std::string png = writeYaml("png.yaml", "p.png");
  EXPECT_EQ(loadError(png), png + ": field 'image': " + path("p.png") +
                                ": PNG images are not supported; convert it to PGM (e.g. 'convert "
                                "map.png map.pgm')");
}

TEST_F(MapLoaderTest, TruncatedBinaryImage) {
  write("m.pgm", "P5\n4 3\n255\n1234567");
  const std::string yaml = writeYaml("m.yaml", "m.pgm");
  EXPECT_EQ(loadError(yaml), yaml + ": field 'image': " + path("m.pgm") +
                                 ": truncated pixel data: a 4 x 3 P5 image with maxval 255 needs "
                                 "12 bytes after the header, found 7 (only 1 of 3 rows complete)");
}

TEST_F(MapLoaderTest, TruncatedAsciiImageAndHeader) {
  write("a.pgm", "P2 2 3 255\n0 0\n0 0\n");
  const std::string a = writeYaml("a.yaml", "a.pgm");
  EXPECT_EQ(loadError(a), a + ": field 'image': " + path("a.pgm") +
                              ": truncated pixel data: expected 6 samples for 2 x 3 pixels, "
                              "found 4 (only 2 of 3 rows complete)");
  write("b.pgm", "P2 2 # width only\n");
  const std::string b = writeYaml("b.yaml", "b.pgm");
  EXPECT_EQ(loadError(b),
            b + ": field 'image': " + path("b.pgm") + ": header ends before the height");
}

TEST_F(MapLoaderTest, SampleAboveMaxval) {
  write("m.pgm", "P2 2 1 15 3 16\n");
  const std::string yaml = writeYaml("m.yaml", "m.pgm");
  EXPECT_EQ(loadError(yaml),
            yaml + ": field 'image': " + path("m.pgm") + ": sample 1 is 16, above maxval 15");
}

TEST_F(MapLoaderTest, LoadMapImageNamesTheImage) {
  MapMetadata meta;
  meta.image = write("m.pgm", "P5 2 2 255\n");
  meta.resolution = 1.0;
  try {
    loadMapImage(meta);
    FAIL() << "no error";
  } catch (const MapLoadError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(meta.image + ": truncated pixel data", 0), 0u)
        << e.what();
  }
}

}  // namespace
}  // namespace pf
