// Output files that are either the complete new file or the untouched old one
// (docs/results.md, "How the file is written").
//
// A file is written as `<output>.tmp-<pid>` beside the output (same folder, so
// the same file system), with POSIX write() in a loop, fsync()ed and closed
// with every status checked, then rename()d over the output; the folder is
// fsync()ed last. Any failure removes the temporary, leaves an earlier output
// byte-identical and throws InputError naming the output the user gave.
//
// Temporaries are registered while they exist, so they are removed on
// exceptions, at exit() and, once InstallTemporaryFileCleanup() has run, on
// SIGINT, SIGTERM and SIGHUP. A temporary of a process killed by SIGKILL (or a
// power cut) stays until the next write of the same output, which removes
// `<output>.tmp-<pid>` files whose process no longer exists.
#pragma once

#include <filesystem>
#include <string_view>

namespace impactlab {

// Refuses, before any work, an output that cannot or must not be written.
// Throws InputError naming `output` (as given) when:
// - it is empty, or an existing folder, or exists and is not a regular file;
// - its parent folder does not exist (or is not a folder);
// - `session_folder` is not empty, exists, and `output` lies inside it (the
//   session is the lab's record and is never written by impactlab; compared
//   on canonical paths, so `reduce .` inside the session is caught too).
void CheckOutputPath(const std::filesystem::path& output,
                     const std::filesystem::path& session_folder = {});

// Writes `bytes` to `path` atomically as described above. If `path` is a
// symbolic link, the file it points to is replaced and the link kept.
// Throws InputError naming `path`; the previous file is then unchanged.
void WriteFileAtomically(const std::filesystem::path& path, std::string_view bytes);

// The temporary name used for `path` by this process: `<path>.tmp-<pid>`.
std::filesystem::path TemporaryPathFor(const std::filesystem::path& path);

// Removes `<path>.tmp-<pid>` files beside `path` whose process no longer
// exists (kill(pid, 0) fails with ESRCH). Temporaries of live processes,
// including this one, are kept. Returns how many were removed; errors while
// listing or removing are ignored (the write that follows reports its own).
int RemoveStaleTemporaries(const std::filesystem::path& path);

// Installs handlers for SIGINT, SIGTERM and SIGHUP that remove the temporary
// being written, then re-raise the signal with its default action (so the
// exit status still says "killed by signal N"). Signals that are ignored at
// the time of the call (nohup, background jobs) stay ignored. Call once, early
// in main(); calling again does nothing.
void InstallTemporaryFileCleanup();

}  // namespace impactlab
