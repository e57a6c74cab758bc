// Replays the committed fuzz corpus (fuzz/corpus/<target>/) through the fuzz targets' entry points
// (fuzz/fuzz_entry.h), compiled normally: no libFuzzer, the Debian decoders of the real binary. Every input
// must end in a result or a bl::input_error, never another exception or a crash (under `make test-sanitize`
// also never a sanitizer report). File names state the expected outcome: bad_* and trunc_* must be rejected,
// crash_* and any_* (inputs found by fuzzing) and libFuzzer's 40-hex-digit names may go either way, every other
// file must load.
#include "../fuzz/fuzz_entry.h"
#include "file_io.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <iostream>
#include <typeinfo>

using namespace bl;

namespace {

// What an input of the corpus is expected to do.
enum class expect { load, reject, either };

expect expected_outcome(const std::string& name) {
  auto starts = [&](const char* p) { return name.rfind(p, 0) == 0; };
  if (starts("bad_") || starts("trunc_")) return expect::reject;
  if (starts("crash_") || starts("any_")) return expect::either;
  bool sha1 = name.size() == 40 && std::all_of(name.begin(), name.end(), [](char c) { return std::isxdigit(c); });
  return sha1 ? expect::either : expect::load;
}

// Silences std::cerr for its lifetime (the parsers warn about unrecognised statements and dropped triangles).
struct quiet_cerr {
  std::streambuf* saved = std::cerr.rdbuf(nullptr);
  ~quiet_cerr() {
    std::cerr.rdbuf(saved);
    std::cerr.clear();
  }
};

// Feeds every file of fuzz/corpus/<target> to the target and checks the outcome its name states.
void replay(fuzz::target t) {
  std::string dir = test::source_path(std::string("fuzz/corpus/") + fuzz::target_name(t));
  REQUIRE(std::filesystem::is_directory(dir));
  std::vector<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  REQUIRE(files.size() >= 5);  // a lost corpus must not pass silently
  fuzz::scratch_dir scratch;
  for (const std::string& file : files) {
    std::string name = std::filesystem::path(file).filename().string();
    std::string bytes = read_file(file);
    std::string outcome = "loaded";
    {
      quiet_cerr quiet;
      try {
        fuzz::feed(t, scratch, reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
      } catch (const input_error& e) {
        outcome = std::string("input_error: ") + e.what();
      } catch (const std::exception& e) {
        outcome = std::string("escaped ") + typeid(e).name() + ": " + e.what();
      }
    }
    INFO(fuzz::target_name(t) << "/" << name << " -> " << outcome);
    CHECK(outcome.rfind("escaped", 0) != 0);
    switch (expected_outcome(name)) {
      case expect::load: CHECK(outcome == "loaded"); break;
      case expect::reject: CHECK(outcome.rfind("input_error: ", 0) == 0); break;
      case expect::either: break;
    }
  }
}

}  // namespace

TEST_CASE("the scene-file fuzz corpus loads or is rejected cleanly", "[fuzz]") { replay(fuzz::target::scene); }
TEST_CASE("the OBJ/MTL fuzz corpus loads or is rejected cleanly", "[fuzz]") { replay(fuzz::target::obj); }
TEST_CASE("the texture fuzz corpus loads or is rejected cleanly", "[fuzz]") { replay(fuzz::target::texture); }
TEST_CASE("the EXR/PFM fuzz corpus loads or is rejected cleanly", "[fuzz]") { replay(fuzz::target::image); }
