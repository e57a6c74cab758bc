// Tests of file_io: atomic replacement, no temporaries left behind, failures that never clobber the
// destination (RLIMIT_FSIZE forces a real mid-write failure, even as root), devices written in place.
#include "errors.h"
#include "file_io.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <csignal>
#include <filesystem>
#include <set>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

using namespace bl;

// Names in directory dir.
static std::set<std::string> entries(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : std::filesystem::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

// The message of the output_error thrown by write_file_atomic(path, bytes), or "" when none is thrown.
static std::string write_error(const std::string& path, const std::string& bytes) {
  try {
    write_file_atomic(path, bytes);
  } catch (const output_error& e) {
    return e.what();
  }
  return "";
}

TEST_CASE("write_file_atomic writes and replaces files and leaves no temporary", "[file_io]") {
  test::temp_dir dir;
  const std::string path = dir / "out.bin";
  std::string bytes(100000, '\0');
  for (size_t i = 0; i < bytes.size(); ++i) bytes[i] = char(i * 7 + 3);
  write_file_atomic(path, bytes);
  CHECK(read_file(path) == bytes);
  REQUIRE(::chmod(path.c_str(), 0640) == 0);
  write_file_atomic(path, "second");
  CHECK(read_file(path) == "second");
  struct stat st {};
  REQUIRE(::stat(path.c_str(), &st) == 0);
  CHECK((st.st_mode & 0777) == 0640);  // the replacement keeps the old file's permissions
  write_file_atomic(path, "");
  CHECK(read_file(path).empty());
  CHECK(entries(dir.path.string()) == std::set<std::string>{"out.bin"});
}

TEST_CASE("write_file_atomic writes a file whose name is near the longest a name may be", "[file_io]") {
  // 250 characters: its temporary, ".NAME.tmp.<pid>.<n>", would pass NAME_MAX (255) if it kept the whole name.
  test::temp_dir dir;
  const std::string name(250, 'n'), path = dir / name;
  write_file_atomic(path, "first");
  CHECK(read_file(path) == "first");
  write_file_atomic(path, "second");
  CHECK(read_file(path) == "second");
  CHECK(entries(dir.path.string()) == std::set<std::string>{name});
}

TEST_CASE("write_file_atomic into a missing directory throws and creates nothing", "[file_io]") {
  test::temp_dir dir;
  const std::string path = dir / "missing/out.exr";
  std::string msg = write_error(path, "data");
  CHECK_THAT(msg, Catch::Contains(path) && Catch::Contains("No such file or directory"));
  CHECK(entries(dir.path.string()).empty());
}

TEST_CASE("a write failing midway keeps the old destination and removes the temporary", "[file_io]") {
  test::temp_dir dir;
  const std::string path = dir / "keep.txt";
  write_file_atomic(path, "old content");
  // Files may grow to 4 KiB only: the 1 MiB write fails with EFBIG (SIGXFSZ ignored) whatever the user.
  auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
  rlimit old_limit{};
  REQUIRE(::getrlimit(RLIMIT_FSIZE, &old_limit) == 0);
  rlimit small = old_limit;
  small.rlim_cur = 4096;
  REQUIRE(::setrlimit(RLIMIT_FSIZE, &small) == 0);
  std::string msg = write_error(path, std::string(1 << 20, 'x'));
  ::setrlimit(RLIMIT_FSIZE, &old_limit);
  std::signal(SIGXFSZ, old_handler);
  CHECK_THAT(msg, Catch::Contains(path) && Catch::Contains("File too large"));
  CHECK(read_file(path) == "old content");
  CHECK(entries(dir.path.string()) == std::set<std::string>{"keep.txt"});
}

TEST_CASE("write_file_atomic reports a full device and writes devices in place", "[file_io]") {
  std::string msg = write_error("/dev/full", "data");
  CHECK_THAT(msg, Catch::Contains("/dev/full") && Catch::Contains("No space left on device"));
  struct stat st {};
  REQUIRE(::stat("/dev/full", &st) == 0);
  CHECK(S_ISCHR(st.st_mode));
  CHECK_NOTHROW(write_file_atomic("/dev/null", "data"));
  REQUIRE(::stat("/dev/null", &st) == 0);
  CHECK(S_ISCHR(st.st_mode));
}

TEST_CASE("write_file_atomic onto a directory throws and leaves it alone", "[file_io]") {
  test::temp_dir dir;
  ::mkdir((dir / "sub").c_str(), 0755);
  CHECK_THAT(write_error(dir / "sub", "data"), Catch::Contains("Is a directory"));
  CHECK_THAT(write_error(dir / "sub/", "data"), Catch::Contains("not a file name"));
  CHECK(entries(dir.path.string()) == std::set<std::string>{"sub"});
  CHECK(entries(dir / "sub").empty());
}

TEST_CASE("write_file_atomic through a symlink replaces the target and keeps the link", "[file_io]") {
  test::temp_dir dir;
  write_file_atomic(dir / "target.txt", "old");
  REQUIRE(::symlink("target.txt", (dir / "link.txt").c_str()) == 0);
  write_file_atomic(dir / "link.txt", "new");
  struct stat st {};
  REQUIRE(::lstat((dir / "link.txt").c_str(), &st) == 0);
  CHECK(S_ISLNK(st.st_mode));
  CHECK(read_file(dir / "target.txt") == "new");
  CHECK(entries(dir.path.string()) == std::set<std::string>{"link.txt", "target.txt"});
}

TEST_CASE("read_file names the file when it cannot read it", "[file_io]") {
  test::temp_dir dir;
  const std::string missing = dir / "nope.json";
  try {
    read_file(missing);
    FAIL("no input_error");
  } catch (const input_error& e) {
    CHECK(e.file == missing);
    CHECK_THAT(e.what(), Catch::StartsWith(missing + ": ") && Catch::Contains("No such file or directory"));
  }
  CHECK_THROWS_AS(read_file(dir.path.string()), input_error);
}
