// file_io: whole-file reads and crash-safe writes, with errors that name the path and the reason.
// Invariants: write_file_atomic never leaves a partial file at the destination, never leaves its temporary
// behind, and leaves an existing destination untouched when it fails. Device nodes and FIFOs (/dev/null,
// /dev/full, a pipe) are written directly, never renamed over; their write errors are still reported.
#pragma once

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace bl {

// The extension of path's file name in ASCII lower case, with its dot (".exr"); "" for none (".exr" alone, "dir.exr/").
std::string lower_extension(const std::string& path);

// Throws input_error naming path unless it is an existing regular file (not a FIFO, device or directory).
void require_regular_file(const std::string& path);
// The whole content of a file; throws input_error(path, reason) when it cannot be opened or read.
std::string read_file(const std::string& path);

// Replaces the file at path with bytes: writes a temporary ".NAME.tmp.<pid>.<n>" in the same directory,
// checks every write, fsyncs and closes it, then renames it over path. A symlink is kept and its target
// replaced (or created, when it does not exist yet). Throws output_error("cannot write PATH: reason") on any failure.
void write_file_atomic(const std::string& path, const std::string& bytes);
// The same for content produced in pieces: `produce` hands each piece to the sink it is given, in order, and the
// pieces go straight to the temporary file (a checkpoint of gigabytes is never held whole in memory). An existing
// non-regular destination (a FIFO, a device) gets the pieces joined, as write_file_atomic writes it.
using byte_sink = std::function<void(const char* data, size_t n)>;
void write_file_atomic_stream(const std::string& path, const std::function<void(const byte_sink&)>& produce);
// An existing FIFO given as an output waits for a process to read it (as any writer of a FIFO does), polling this
// function meanwhile (a count of signals received): when it changes during the wait, a signal arrived and the wait
// gives up with a write_failure. A signal that came before (an interrupted render writing its passes) does not stop
// the wait. The render installs it with its signal handlers; without it the wait is not interruptible from here.
// Once a signal has ended a wait, a later FIFO output that no process reads fails at once, and one whose reader
// takes nothing for a second fails then.
void set_fifo_wait_check(int (*signal_count)());

// The file a write to path creates or replaces: symbolic links followed (a dangling one to the file it names,
// which the write creates), "." and ".." resolved, absolute.
std::string output_target(const std::string& path);
// The same file, whether or not it exists yet (symbolic links, dangling ones too, and "." / ".." resolved).
bool same_file(const std::string& a, const std::string& b);
// Refuses (usage_error, exit 2, before any work) outputs that would overwrite one of the inputs or one another.
// Files are (path, role) pairs; the one overlap allowed is a checkpoint (output role "checkpoint") resumed from
// (input role resumed_role) and written again.
inline constexpr const char* resumed_role = "checkpoint resumed from";
void check_distinct_outputs(const std::vector<std::pair<std::string, std::string>>& outputs,
                            const std::vector<std::pair<std::string, std::string>>& inputs);

}  // namespace bl
