// Replays the committed fuzz inputs (seed corpora and the crash reproducers
// of bugs already fixed) through the fuzz targets in an ordinary test build,
// so that a regression shows up in every test run, not only under libFuzzer.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

// The targets' LLVMFuzzerTestOneInput, renamed at compile time (CMakeLists.txt).
extern "C" int FuzzCoreOneInput(const uint8_t* data, std::size_t size);
extern "C" int FuzzMapLoaderOneInput(const uint8_t* data, std::size_t size);

namespace {

namespace fs = std::filesystem;

std::vector<fs::path> inputs(const std::string& dir, const std::string& prefix = "") {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(fs::path(PF_FUZZ_DIR) / dir)) {
    const std::string name = e.path().filename().string();
    if (e.is_regular_file() && name.rfind(prefix, 0) == 0 && name != "README.md") {
      out.push_back(e.path());
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

void replay(const std::vector<fs::path>& files, int (*target)(const uint8_t*, std::size_t)) {
  ASSERT_FALSE(files.empty());
  for (const fs::path& f : files) {
    SCOPED_TRACE(f.string());
    std::ifstream in(f, std::ios::binary);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)),
                                  std::istreambuf_iterator<char>());
    // A crash ends the test binary; returning is the pass.
    EXPECT_EQ(0, target(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size()));
  }
}

TEST(FuzzReplay, CoreSeedCorpus) { replay(inputs("corpus/fuzz_core"), FuzzCoreOneInput); }

TEST(FuzzReplay, MapLoaderSeedCorpus) {
  replay(inputs("corpus/fuzz_map_loader"), FuzzMapLoaderOneInput);
}

TEST(FuzzReplay, FixedCoreCrashes) { replay(inputs("crashes", "fuzz_core-"), FuzzCoreOneInput); }

TEST(FuzzReplay, FixedMapLoaderCrashes) {
  replay(inputs("crashes", "fuzz_map_loader-"), FuzzMapLoaderOneInput);
}

}  // namespace
