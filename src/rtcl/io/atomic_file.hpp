// Output files are written whole or not at all: the data goes to a temporary
// file beside the target (same directory, so the final rename(2) is atomic on
// POSIX file systems), is flushed to disk, and only then replaces the target;
// the directory is flushed after the rename. On any failure the temporary
// file is removed and the target is untouched.
// - A target that is a symbolic link: the file it points to is replaced, the
//   link stays.
// - An existing target keeps its permission bits; a new one gets 0666 less
//   the umask.
// - Temporary files are hidden, named ".STEM.tmp-PID-RANDOM.EXT" (unique per
//   process and call), removed if the process is stopped by SIGINT, SIGTERM,
//   SIGHUP or SIGQUIT (temp_cleanup.hpp); one left by a process killed
//   outright (SIGKILL) is removed by the next write to the same target.
#pragma once

#include <cstddef>
#include <functional>
#include <span>
#include <string>

namespace rtcl {

// Writes `bytes` to `path` atomically. Throws Error naming `path` when the
// directory is missing or not writable, the disk is full, or the rename fails.
void write_file_atomically(const std::string& path, std::span<const std::byte> bytes);

// Calls write(temp_path), which must create the complete file content at
// temp_path (it may reopen or truncate it), then renames temp_path to `path`.
// temp_path lies in the target's directory and ends with the target's
// extension (".png" stays ".png"), so writers that choose a format by
// extension see the same one. If write throws, its exception propagates
// after the temporary file has been removed.
void write_file_atomically(const std::string& path, const std::function<void(const std::string& temp_path)>& write);

// Throws Error naming `path` unless its directory exists and is writable and
// `path` itself is not a directory: a cheap check before long work, not a
// guarantee (the atomic write still reports its own failures).
void check_writable(const std::string& path);

}  // namespace rtcl
