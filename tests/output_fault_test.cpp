// Output faults as users meet them, driving the binary (SPEC.md section 4): an output or log path that cannot be
// written fails with exit 1 before any rendering and names the path; a write that fails late (full device, file
// size limit) exits 1 with the reason; an existing file at the destination is never replaced by a partial one and
// no temporary file is left behind. Late failures are forced with /dev/full behind a symlink and with
// RLIMIT_FSIZE in a forked child (a real mid-write EFBIG, whatever the user, root included).
#include "file_io.h"
#include "test_util.h"

#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>

using namespace bl;
using namespace bl::test;

namespace {

namespace fs = std::filesystem;

// A tiny valid scene (a floor and a lamp) in a fresh folder, and its scene file.
struct fault_scene {
  temp_dir dir;
  std::string json;
  fault_scene() {
    write_text(dir / "box.obj",
               "mtllib box.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n"
               "v -0.2 1 -0.2\nv 0.2 1 -0.2\nv 0.2 1 0.2\nv -0.2 1 0.2\n"
               "usemtl floor\nf 1 4 3 2\nusemtl lamp\nf 5 6 7 8\n");
    write_text(dir / "box.mtl", "newmtl floor\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 5 5 5\n");
    json = dir / "scene.json";
    write_text(json, "{\"mesh\": \"box.obj\", \"camera\": {\"eye\": [0, 0.5, 2], \"target\": [0, 0, 0]},"
                     " \"image\": {\"width\": 16, \"height\": 12}, \"render\": {\"spp\": 2, \"max_depth\": 2}}");
  }
  // Names in the folder that look like write_file_atomic's temporaries.
  std::vector<std::string> temporaries() const {
    std::vector<std::string> found;
    for (const auto& e : fs::recursive_directory_iterator(dir.path)) {
      std::string name = e.path().filename().string();
      if (name.find(".tmp.") != std::string::npos) found.push_back(name);
    }
    return found;
  }
};

// The whole content of a file ("" when it cannot be read).
std::string contents(const std::string& path) {
  try {
    return read_file(path);
  } catch (const std::exception&) {
    return "";
  }
}

// Runs bayeslight with args and returns the result and the wall time it took, in seconds.
run_result run_timed(const std::string& args, double& seconds) {
  auto t0 = std::chrono::steady_clock::now();
  run_result r = run_bayeslight(args);
  seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

// Runs bayeslight with args in a forked child whose files may not grow beyond fsize_limit bytes. SIGXFSZ is
// ignored there, so an oversized write fails with EFBIG instead of killing the process (as a full disk fails
// with ENOSPC). stdout and stderr come back through a pipe, which the limit does not apply to.
run_result run_with_file_size_limit(const std::vector<std::string>& args, rlim_t fsize_limit) {
  std::vector<std::string> argv_text = {BAYESLIGHT_BINARY};
  argv_text.insert(argv_text.end(), args.begin(), args.end());
  std::vector<char*> argv;  // built before fork: the child only calls async-signal-safe functions
  for (std::string& a : argv_text) argv.push_back(a.data());
  argv.push_back(nullptr);
  run_result r;
  int fds[2];
  if (::pipe(fds) != 0) return r;
  pid_t pid = ::fork();
  if (pid == 0) {
    ::dup2(fds[1], 1);
    ::dup2(fds[1], 2);
    ::close(fds[0]);
    ::close(fds[1]);
    ::signal(SIGXFSZ, SIG_IGN);  // an ignored disposition survives exec
    rlimit lim{fsize_limit, fsize_limit};
    if (::setrlimit(RLIMIT_FSIZE, &lim) != 0) ::_exit(126);
    ::execv(argv[0], argv.data());
    ::_exit(127);
  }
  ::close(fds[1]);
  if (pid < 0) {
    ::close(fds[0]);
    return r;
  }
  char buf[4096];
  ssize_t n;
  while ((n = ::read(fds[0], buf, sizeof buf)) > 0 || (n < 0 && errno == EINTR))
    if (n > 0) r.output.append(buf, size_t(n));
  ::close(fds[0]);
  int st = 0;
  while (::waitpid(pid, &st, 0) < 0 && errno == EINTR) {
  }
  r.status = WIFEXITED(st) ? WEXITSTATUS(st) : 128 + WTERMSIG(st);
  return r;
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A render that would take far longer than any check allows if it started (--time 100): a failure that returns
// within a few seconds happened before rendering.
const std::string long_render = " --sampler power --time 100 --quiet";

}  // namespace

TEST_CASE("an output in a missing directory fails before rendering and names the path", "[faults]") {
  fault_scene s;
  write_text(s.dir / "keep.exr", "existing");
  const std::string missing = s.dir / "no/such/dir/out.exr";
  double seconds = 0;
  auto r = run_timed("render " + s.json + long_render + " -o " + (s.dir / "keep.exr") + " -o " + missing, seconds);
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(contains(r.output, missing));
  CHECK(contains(r.output, "does not exist"));
  CHECK(seconds < 30);
  CHECK(contents(s.dir / "keep.exr") == "existing");  // the valid output listed first was not written either
  CHECK(!fs::exists(s.dir / "no"));
  CHECK(s.temporaries().empty());
}

TEST_CASE("a log in a missing directory fails before rendering and names the path", "[faults]") {
  fault_scene s;
  write_text(s.dir / "keep.pfm", "existing");
  const std::string missing = s.dir / "missing/log.csv";
  double seconds = 0;
  auto r = run_timed("render " + s.json + long_render + " -o " + (s.dir / "keep.pfm") + " --log " + missing, seconds);
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(contains(r.output, missing));
  CHECK(seconds < 30);
  CHECK(contents(s.dir / "keep.pfm") == "existing");
  CHECK(s.temporaries().empty());
}

TEST_CASE("an output or log that is a directory fails before rendering and is left alone", "[faults]") {
  fault_scene s;
  fs::create_directory(s.dir / "out.exr");
  write_text(s.dir / "out.exr/inside.txt", "inside");
  fs::create_directory(s.dir / "log.csv");
  for (const std::string& args : {" -o " + (s.dir / "out.exr"), " -o " + (s.dir / "x.pfm") + " --log " +
                                                                    (s.dir / "log.csv")}) {
    double seconds = 0;
    auto r = run_timed("render " + s.json + long_render + args, seconds);
    INFO(args << "\n" << r.output);
    CHECK(r.status == 1);
    CHECK(contains(r.output, "is a directory"));
    CHECK(seconds < 30);
  }
  CHECK(fs::is_directory(s.dir / "out.exr"));
  CHECK(contents(s.dir / "out.exr/inside.txt") == "inside");
  CHECK(fs::is_directory(s.dir / "log.csv"));
  CHECK(!fs::exists(s.dir / "x.pfm"));
  CHECK(s.temporaries().empty());
}

TEST_CASE("a full device at write time exits 1 with the reason and keeps the link", "[faults]") {
  fault_scene s;
  // An .exr name that links to /dev/full: the path passes every check, the write itself fails (ENOSPC).
  const std::string full = s.dir / "full.exr";
  REQUIRE(::symlink("/dev/full", full.c_str()) == 0);
  auto r = run_bayeslight("render " + s.json + " --sampler power --quiet -o " + full);
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(contains(r.output, full));
  CHECK(contains(r.output, "No space left on device"));
  CHECK(fs::is_symlink(full));
  CHECK(fs::read_symlink(full) == "/dev/full");
  CHECK(s.temporaries().empty());
  // /dev/full itself has no image extension: a bad command line (exit 2) that names it, before rendering.
  auto d = run_bayeslight("render " + s.json + " --quiet -o /dev/full");
  INFO(d.output);
  CHECK(d.status == 2);
  CHECK(contains(d.output, "/dev/full"));
  CHECK(contains(d.output, "unknown image format"));
}

TEST_CASE("a log that cannot be written at write time exits 1 after writing the image", "[faults]") {
  fault_scene s;
  const std::string log = s.dir / "log.csv";
  REQUIRE(::symlink("/dev/full", log.c_str()) == 0);
  auto r = run_bayeslight("render " + s.json + " --sampler power --quiet -o " + (s.dir / "img.pfm") + " --log " + log);
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(contains(r.output, log));
  CHECK(contains(r.output, "No space left on device"));
  CHECK(fs::file_size(s.dir / "img.pfm") > 16 * 12 * 12);  // the complete image, written before the log
  CHECK(s.temporaries().empty());
}

TEST_CASE("a checkpoint that cannot be written is reported, and the render and its image go on", "[faults]") {
  fault_scene s;
  const std::string ck = s.dir / "ck.bin";
  REQUIRE(::symlink("/dev/full", ck.c_str()) == 0);
  // Every pass's checkpoint (--checkpoint-every 0) and the last one fail; the image is that of a render without.
  auto r = run_bayeslight("render " + s.json + " --sampler bayes --quiet -o " + (s.dir / "img.pfm") + " --checkpoint " +
                          ck + " --checkpoint-every 0");
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(contains(r.output, "warning: cannot write " + ck));
  CHECK(contains(r.output, "No space left on device"));
  REQUIRE(run_bayeslight("render " + s.json + " --sampler bayes --quiet -o " + (s.dir / "plain.pfm")).status == 0);
  CHECK(read_file(s.dir / "img.pfm") == read_file(s.dir / "plain.pfm"));
  CHECK(s.temporaries().empty());
}

TEST_CASE("a write that fails midway never clobbers the existing output", "[faults]") {
  fault_scene s;
  const std::string out = s.dir / "out.pfm", png = s.dir / "out.png", log = s.dir / "log.csv";
  write_text(out, "old image");
  write_text(png, "old png");
  write_text(log, "old log");
  // 64x48 RGB floats are 36 KiB: far over the 4 KiB limit, so the write fails with EFBIG partway through.
  auto r = run_with_file_size_limit({"render", s.json, "--sampler", "power", "--quiet", "--width", "64", "--height",
                                     "48", "-o", out, "-o", png, "--log", log},
                                    4096);
  INFO(r.output);
  CHECK(r.status == 1);
  CHECK(contains(r.output, out));
  CHECK(contains(r.output, "File too large"));
  CHECK(contents(out) == "old image");
  // The outputs after the failed one are still written (small enough for the limit): one failure loses no other.
  CHECK(contents(png).rfind("\x89PNG", 0) == 0);
  CHECK(contents(log).rfind("sampler,pass,spp", 0) == 0);
  CHECK(s.temporaries().empty());
  // The same render without the limit replaces all three.
  auto ok = run_bayeslight("render " + s.json + " --sampler power --quiet --width 64 --height 48 -o " + out + " -o " +
                           png + " --log " + log);
  REQUIRE(ok.status == 0);
  CHECK(fs::file_size(out) > 64 * 48 * 12);
  CHECK(contents(png).rfind("\x89PNG", 0) == 0);
  CHECK(contents(log).rfind("sampler,pass,spp", 0) == 0);
}
