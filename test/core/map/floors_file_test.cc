// loadFloorsFile: a building's floors, their maps resolved against the
// file's folder, and a clear message for every way the file can be wrong.
#include "pf_localization/core/map/floors_file.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace pf {
namespace {

namespace fs = std::filesystem;

class FloorsFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / "pf_floors_file_test" / info->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_ / "maps");
    for (const char* map : {"maps/a.yaml", "maps/b.yaml"})
      std::ofstream(dir_ / map) << "image: x\n";
  }
  std::string write(const std::string& text) {
    const fs::path p = dir_ / "floors.yaml";
    std::ofstream(p) << text;
    return p.string();
  }
  // The message loadFloorsFile throws for `text` (empty when it does not).
  std::string errorOf(const std::string& text) {
    try {
      loadFloorsFile(write(text));
    } catch (const FloorsFileError& e) {
      return e.what();
    }
    return "";
  }
  fs::path dir_;
};

TEST_F(FloorsFileTest, ReadsTheFloorsWithTheirMapsBesideTheFile) {
  const FloorsFile f = loadFloorsFile(
      write("floors:\n  - {name: ground, map: maps/a.yaml}\n  - {name: upper, map: maps/b.yaml}\n"
            "initial_floor: upper\n"));
  ASSERT_EQ(2u, f.floors.size());
  EXPECT_EQ("ground", f.floors[0].name);
  EXPECT_EQ((dir_ / "maps/a.yaml").string(), f.floors[0].map);
  EXPECT_EQ((dir_ / "maps/b.yaml").string(), f.floors[1].map);
  EXPECT_EQ(1u, f.initial);
  EXPECT_EQ(1u, f.find("upper"));
  EXPECT_FALSE(f.find("roof").has_value());
  EXPECT_EQ("ground, upper", f.names());
  EXPECT_TRUE(isFloorsFile(write("floors: []\n")));
  EXPECT_FALSE(isFloorsFile((dir_ / "maps/a.yaml").string()));
  EXPECT_FALSE(isFloorsFile((dir_ / "none.yaml").string()));
}

TEST_F(FloorsFileTest, StartsOnTheFirstFloorByDefaultAndTakesAbsolutePaths) {
  const std::string absolute = (dir_ / "maps/b.yaml").string();
  const FloorsFile f = loadFloorsFile(write("floors:\n  - {name: only, map: " + absolute + "}\n"));
  EXPECT_EQ(0u, f.initial);
  EXPECT_EQ(absolute, f.floors[0].map);
}

TEST_F(FloorsFileTest, SaysWhatIsWrong) {
  EXPECT_NE(std::string::npos, errorOf("floors: []\n").find("needs 'floors'"));
  EXPECT_NE(std::string::npos, errorOf("[1, 2]\n").find("needs 'floors'"));
  EXPECT_NE(std::string::npos, errorOf("floors: [\n").find("not YAML"));
  EXPECT_NE(std::string::npos,
            errorOf("floors:\n  - {map: maps/a.yaml}\n").find("floor 1: needs a non-empty 'name'"));
  EXPECT_NE(
      std::string::npos,
      errorOf("floors:\n  - {name: a, map: maps/a.yaml}\n  - x\n").find("floor 2: must be a map"));
  EXPECT_NE(std::string::npos,
            errorOf("floors:\n  - {name: a, map: maps/none.yaml}\n").find("no map file"));
  EXPECT_NE(std::string::npos,
            errorOf("floors:\n  - {name: a, map: maps/a.yaml}\n  - {name: a, map: maps/b.yaml}\n")
                .find("a second floor named 'a'"));
  EXPECT_NE(std::string::npos, errorOf("floors:\n  - {name: a, map: maps/a.yaml}\n"
                                       "initial_floor: roof\n")
                                   .find("initial_floor must name a floor (a)"));
  EXPECT_THROW(loadFloorsFile((dir_ / "none.yaml").string()), FloorsFileError);
}

}  // namespace
}  // namespace pf
