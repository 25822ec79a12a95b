// Opening the files a manifest names, so that nothing outside the session
// folder is ever read and nothing can make the reducer wait forever.
//
// The manifest reader checks each path once (manifest.h); between that check
// and the read a file could be swapped for a symbolic link leading out, or for
// a named pipe that blocks open() until a writer comes. So the check is made
// again on the descriptor itself: the file is opened beneath the folder
// (openat2 with RESOLVE_BENEATH where the kernel has it, else opened and its
// descriptor's real path compared with the folder), without blocking, and
// refused unless it is a regular file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

namespace impactlab {

// An open, read-only descriptor of a regular file inside a session folder.
class SessionFile {
 public:
  // Throws InputError naming `file` when it leads outside `folder` (through
  // "..", an absolute path or a symbolic link), is missing, or is not a
  // regular file (a folder, a named pipe, a device, a socket). An empty
  // `folder` puts no bound on where the file is (a file the user named on the
  // command line), but it must still be a regular file.
  SessionFile(const std::filesystem::path& folder, const std::filesystem::path& file);
  SessionFile(SessionFile&& other) noexcept;
  SessionFile& operator=(SessionFile&& other) noexcept;
  SessionFile(const SessionFile&) = delete;
  SessionFile& operator=(const SessionFile&) = delete;
  ~SessionFile();

  int descriptor() const { return fd_; }
  const std::filesystem::path& path() const { return path_; }
  std::uintmax_t size() const { return size_; }

  // The whole file. Throws InputError when it is larger than `max_bytes` or
  // cannot be read.
  std::vector<unsigned char> ReadAll(std::uintmax_t max_bytes) const;

  // Gives the descriptor away (e.g. to fdopen); the object no longer owns it.
  int Release();

 private:
  int fd_ = -1;
  std::filesystem::path path_;
  std::uintmax_t size_ = 0;
};

// The largest file the reducer reads whole: photos and CSV traces. A scan of
// a print at 1200 dpi as a 16-bit PNG is about 100 MB; this leaves room.
inline constexpr std::uintmax_t kMaxSessionFileBytes = std::uintmax_t{1} << 30;  // 1 GiB

// True when `inner` is `folder` or lies below it, compared part by part; both
// canonical (symbolic links resolved) for the answer to mean anything.
bool IsInsideFolder(const std::filesystem::path& inner, const std::filesystem::path& folder);

// Reads `file` (inside `folder`) whole, with the checks above.
std::vector<unsigned char> ReadSessionFile(const std::filesystem::path& folder,
                                           const std::filesystem::path& file,
                                           std::uintmax_t max_bytes = kMaxSessionFileBytes);

}  // namespace impactlab
