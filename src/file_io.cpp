// file_io: whole-file reads and atomic writes on POSIX file descriptors.
// Every write, fsync and close is checked (a full disk surfaces as ENOSPC from one of them); EINTR is retried,
// so a SIGINT handler that does not restart system calls cannot truncate an output.
#include "file_io.h"

#include "errors.h"

#include <atomic>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <sys/stat.h>
#include <thread>
#include <unistd.h>

namespace bl {

// The message of errno value err.
static std::string reason(int err) { return std::strerror(err); }

// Thrown for every write failure: "cannot write PATH: reason".
static output_error write_failure(const std::string& path, const std::string& why) {
  return output_error("cannot write " + path + ": " + why);
}

// Writes all n bytes to fd, retrying short writes and EINTR; returns 0 or the errno of the failure.
static int write_all(int fd, const char* data, size_t n) {
  while (n > 0) {
    ssize_t k = ::write(fd, data, n);
    if (k < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (k == 0) return EIO;  // a regular file or device that accepts nothing: do not spin
    data += k;
    n -= static_cast<size_t>(k);
  }
  return 0;
}

// Closes fd; returns 0 or the errno of the failure (EINTR counts as closed: Linux always releases the fd).
static int close_checked(int fd) {
  if (::close(fd) == 0 || errno == EINTR) return 0;
  return errno;
}

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = char(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

void require_regular_file(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) throw input_error(path, reason(errno));
  if (S_ISDIR(st.st_mode)) throw input_error(path, "is a directory");
  if (!S_ISREG(st.st_mode)) throw input_error(path, "not a regular file");
}

std::string read_file(const std::string& path) {
  // O_NONBLOCK: opening a FIFO must not wait for a writer; only regular files are read (a FIFO or a device such
  // as /dev/urandom would block or never end).
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) throw input_error(path, reason(errno));
  std::string bytes;
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    bool dir = S_ISDIR(st.st_mode);
    ::close(fd);
    throw input_error(path, dir ? "is a directory" : "not a regular file");
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  if (st.st_size > 0) bytes.reserve(size_t(st.st_size));
  char buf[1 << 16];
  for (;;) {
    ssize_t k = ::read(fd, buf, sizeof buf);
    if (k < 0 && errno == EINTR) continue;
    if (k < 0) {
      int err = errno;
      ::close(fd);
      throw input_error(path, reason(err));
    }
    if (k == 0) break;
    bytes.append(buf, size_t(k));
  }
  ::close(fd);
  return bytes;
}

static int (*g_fifo_wait_check)() = nullptr;
void set_fifo_wait_check(int (*signal_count)()) { g_fifo_wait_check = signal_count; }

// Whether a signal arrived since the count was signals_before (the wait for a FIFO's reader ends on one).
static bool signal_since(int signals_before) {
  return g_fifo_wait_check && g_fifo_wait_check() != signals_before;
}
// Set once a signal has ended a wait: a later FIFO output without a reader then fails at once (one SIGINT given to
// end a wait must not have to be given again for every checkpoint and output after it).
static std::atomic<bool> g_fifo_wait_given_up{false};

// Writes all n bytes to a FIFO opened non-blocking: while the pipe is full (its reader holds it open without
// reading yet), polls every 10 ms; a signal arriving meanwhile ends the wait (returns EINTR and sets interrupted).
static int write_all_fifo(const std::string& path, int fd, const char* data, size_t n, int signals_before,
                          bool& interrupted) {
  // After a signal ended an earlier wait, a reader that takes nothing for a second is given up too (one that reads
  // keeps the write going).
  auto progress = std::chrono::steady_clock::now();
  bool said = false;
  while (n > 0) {
    ssize_t k = ::write(fd, data, n);
    if (k < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) return errno;
      if (!said && !g_fifo_wait_given_up && std::chrono::steady_clock::now() - progress > std::chrono::seconds(1)) {
        // (A wait without a word looks like a hang; and tests signal once they read this.)
        stderr_text() << "bayeslight: waiting for the process reading " << path
                      << " to take the rest (a signal gives up on it)\n";
        said = true;
      }
      if (signal_since(signals_before) ||
          (g_fifo_wait_given_up && std::chrono::steady_clock::now() - progress > std::chrono::seconds(1))) {
        interrupted = true;
        g_fifo_wait_given_up = true;
        return EINTR;
      }
      pollfd p{fd, POLLOUT, 0};
      (void)::poll(&p, 1, 10);
      continue;
    }
    data += k;
    n -= static_cast<size_t>(k);
    progress = std::chrono::steady_clock::now();
  }
  return 0;
}

// Writes bytes straight into an existing non-regular file (device, FIFO, socket): renaming over it would
// replace the node itself. Errors such as ENOSPC from /dev/full are reported like any other. A FIFO is opened
// and written without blocking, retried every 10 ms while no process reads it or its pipe is full: a blocking
// open or write waited deaf to SIGINT and SIGTERM (their handlers only set a flag, and the call restarted); now
// the wait ends when a signal arrives. A reader that closes early is a write failure (EPIPE), not a SIGPIPE that
// kills the process without a word: SIGPIPE is blocked on this thread while it writes, and the one the failed
// write raised is taken back.
static void write_direct(const std::string& path, const std::string& bytes, bool fifo) {
  int fd = -1;
  const int signals_before = g_fifo_wait_check ? g_fifo_wait_check() : 0;
  const auto wait_start = std::chrono::steady_clock::now();
  for (bool said = false;;) {
    fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC | (fifo ? O_NONBLOCK : 0));
    if (fd >= 0 || !fifo || errno != ENXIO) break;
    if (g_fifo_wait_given_up)
      throw write_failure(path, "no process reads this FIFO (a signal ended an earlier wait for a reader)");
    if (signal_since(signals_before)) {
      g_fifo_wait_given_up = true;
      throw write_failure(path, "interrupted while waiting for a process to read this FIFO");
    }
    if (!said && std::chrono::steady_clock::now() - wait_start > std::chrono::seconds(1)) {
      stderr_text() << "bayeslight: waiting for a process to read " << path << " (a signal gives up on it)\n";
      said = true;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (fd < 0) throw write_failure(path, reason(errno));
  sigset_t pipe_signal, old_mask, pending;
  sigemptyset(&pipe_signal);
  sigaddset(&pipe_signal, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_signal, &old_mask);
  sigemptyset(&pending);
  sigpending(&pending);
  const bool pipe_pending_before = sigismember(&pending, SIGPIPE) == 1;
  bool interrupted = false;
  int err = fifo ? write_all_fifo(path, fd, bytes.data(), bytes.size(), signals_before, interrupted)
                 : write_all(fd, bytes.data(), bytes.size());
  if (err == EPIPE && !pipe_pending_before) {
    const timespec now{0, 0};
    while (sigtimedwait(&pipe_signal, nullptr, &now) < 0 && errno == EINTR) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &old_mask, nullptr);
  int cerr = close_checked(fd);
  if (err == 0) err = cerr;
  if (interrupted) throw write_failure(path, "interrupted while waiting for the process reading this FIFO to take the rest");
  if (err == EPIPE) throw write_failure(path, "the process reading it closed it before the end (broken pipe)");
  if (err != 0) throw write_failure(path, reason(err));
}

// Creates a fresh temporary file next to target (O_EXCL: never reuses an existing name); returns its fd and
// sets tmp_path, or returns -1 with errno set.
static int create_temporary(const std::string& target, std::string& tmp_path) {
  // Process-wide counter: unique names for concurrent writes from several threads of this process.
  static std::atomic<unsigned> counter{0};
  size_t slash = target.rfind('/');
  std::string dir = slash == std::string::npos ? std::string() : target.substr(0, slash + 1);
  std::string name = slash == std::string::npos ? target : target.substr(slash + 1);
  if (name.size() > 200) name.resize(200);  // keep ".NAME.tmp.<pid>.<n>" under NAME_MAX
  for (int attempt = 0; attempt < 100; ++attempt) {
    tmp_path = dir + "." + name + ".tmp." + std::to_string(long(::getpid())) + "." +
               std::to_string(counter.fetch_add(1));
    int fd = ::open(tmp_path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0 || errno != EEXIST) return fd;
  }
  errno = EEXIST;
  return -1;
}

// The file a write to path creates or replaces: path with its symbolic links followed, the last ones too when
// their target does not exist yet (a write through a dangling link creates its target, as a shell redirection
// does), "." and ".." resolved. Links that loop are left as they are after 40 steps (the write then fails).
static std::filesystem::path write_target(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  if (ec) return fs::path(path).lexically_normal();
  for (int hops = 0; hops < 40; hops++) {
    p = fs::weakly_canonical(p, ec);  // links in the existing part (a last one that resolves, too)
    if (ec) return fs::path(path).lexically_normal();
    if (!fs::is_symlink(fs::symlink_status(p, ec))) return p;
    fs::path to = fs::read_symlink(p, ec);  // a dangling link: where it points
    if (ec) return p;
    p = to.is_absolute() ? to : p.parent_path() / to;
  }
  return p;
}

std::string output_target(const std::string& path) { return write_target(path).string(); }

// The file a symlink at path finally names (also one that does not exist yet), so that the rename replaces or
// creates the target and keeps the link; path itself when it is no symlink.
static std::string rename_target(const std::string& path) {
  struct stat lst {};
  if (::lstat(path.c_str(), &lst) != 0 || !S_ISLNK(lst.st_mode)) return path;
  return output_target(path);
}

void write_file_atomic(const std::string& path, const std::string& bytes) {
  write_file_atomic_stream(path, [&](const byte_sink& sink) { sink(bytes.data(), bytes.size()); });
}

void write_file_atomic_stream(const std::string& path, const std::function<void(const byte_sink&)>& produce) {
  if (path.empty() || path.back() == '/') throw write_failure(path, "not a file name");
  struct stat st {};
  const bool exists = ::stat(path.c_str(), &st) == 0;
  if (exists && !S_ISREG(st.st_mode)) {
    std::string bytes;
    produce([&](const char* data, size_t n) { bytes.append(data, n); });
    write_direct(path, bytes, S_ISFIFO(st.st_mode));
    return;
  }
  const std::string target = rename_target(path);

  std::string tmp;
  int fd = create_temporary(target, tmp);
  if (fd < 0) throw write_failure(path, reason(errno));
  if (exists) (void)::fchmod(fd, st.st_mode & 07777);  // a replaced file keeps its permissions (best effort)
  int err = 0;  // the first failure; later pieces are dropped
  try {
    produce([&](const char* data, size_t n) {
      if (err == 0) err = write_all(fd, data, n);
    });
  } catch (...) {
    ::close(fd);
    ::unlink(tmp.c_str());
    throw;
  }
  // Delayed-allocation and network file systems may report ENOSPC/EIO only here; EINVAL means no fsync support.
  if (err == 0 && ::fsync(fd) != 0 && errno != EINVAL) err = errno;
  int cerr = close_checked(fd);
  if (err == 0) err = cerr;
  if (err == 0 && ::rename(tmp.c_str(), target.c_str()) != 0) err = errno;
  if (err != 0) {
    ::unlink(tmp.c_str());
    throw write_failure(path, reason(err));
  }
}

bool same_file(const std::string& a, const std::string& b) { return write_target(a) == write_target(b); }

void check_distinct_outputs(const std::vector<std::pair<std::string, std::string>>& outputs,
                            const std::vector<std::pair<std::string, std::string>>& inputs) {
  for (size_t i = 0; i < outputs.size(); i++) {
    for (const auto& in : inputs)
      if (!(in.second == resumed_role && outputs[i].second == "checkpoint") && same_file(outputs[i].first, in.first))
        throw usage_error(outputs[i].second + " " + outputs[i].first + " would overwrite the " + in.second + " " +
                          in.first);
    for (size_t j = 0; j < i; j++)
      if (same_file(outputs[i].first, outputs[j].first))
        throw usage_error(outputs[i].second + " " + outputs[i].first +
                          (outputs[i] == outputs[j] ? std::string(" is given twice")
                                                    : " is also the " + outputs[j].second + " " + outputs[j].first));
  }
}

}  // namespace bl
