#include "io/session_file.h"

#include <fcntl.h>
#include <linux/openat2.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <optional>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "io/errors.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;

[[noreturn]] void Refuse(const fs::path& file, const std::string& problem) {
  throw InputError({file, "", std::nullopt}, problem);
}

// Closes a descriptor at the end of a scope unless released.
class FdGuard {
 public:
  explicit FdGuard(int fd) : fd_(fd) {}
  ~FdGuard() {
    if (fd_ >= 0) ::close(fd_);
  }
  FdGuard(const FdGuard&) = delete;
  FdGuard& operator=(const FdGuard&) = delete;
  int get() const { return fd_; }
  int release() { return std::exchange(fd_, -1); }

 private:
  int fd_;
};

// `file` as a path below `folder`, or nothing when it is not one.
std::optional<fs::path> RelativeToFolder(const fs::path& folder, const fs::path& file) {
  const fs::path relative = file.lexically_normal().lexically_relative(folder.lexically_normal());
  if (relative.empty() || relative.is_absolute() || relative == ".") return std::nullopt;
  if (*relative.begin() == "..") return std::nullopt;
  return relative;
}

std::string FileTypeName(mode_t mode) {
  if (S_ISDIR(mode)) return "a folder";
  if (S_ISFIFO(mode)) return "a named pipe";
  if (S_ISCHR(mode) || S_ISBLK(mode)) return "a device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// Never blocks (a named pipe opens at once with O_NONBLOCK and is refused
// afterwards by its type); no controlling terminal; closed on exec.
constexpr int kOpenFlags = O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC;

// openat2 with RESOLVE_BENEATH: the kernel refuses any step out of the folder,
// symbolic links included, in the same call that opens. -1 with errno ENOSYS
// (or EPERM under some sandboxes) where the call is not available.
int OpenBeneath(int folder_fd, const fs::path& relative) {
  open_how how{};
  how.flags = kOpenFlags;
  how.resolve = RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS;
  return static_cast<int>(::syscall(SYS_openat2, folder_fd, relative.c_str(), &how, sizeof(how)));
}

// Where no openat2 is available: open, then ask the descriptor where it is.
int OpenThenCheck(int folder_fd, const fs::path& folder, const fs::path& relative,
                  const fs::path& file) {
  FdGuard fd(::openat(folder_fd, relative.c_str(), kOpenFlags));
  if (fd.get() < 0) return -1;
  std::error_code error;
  const fs::path real = fs::read_symlink(fmt::format("/proc/self/fd/{}", fd.get()), error);
  const fs::path where = error ? fs::canonical(file, error) : real;
  if (error || !IsInsideFolder(where, fs::canonical(folder, error)) || error) {
    errno = EXDEV;
    return -1;
  }
  return fd.release();
}

// A descriptor of `file`, opened beneath `folder` (anywhere when empty);
// -1 with errno when it cannot be.
int OpenFile(const fs::path& folder, const fs::path& file) {
  if (folder.empty()) return ::open(file.c_str(), kOpenFlags);
  const std::optional<fs::path> relative = RelativeToFolder(folder, file);
  if (!relative) Refuse(file, "refused: the file is not inside the session folder");
  FdGuard folder_fd(::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (folder_fd.get() < 0) {
    Refuse(folder, fmt::format("cannot open the session folder: {}", std::strerror(errno)));
  }
  const int fd = OpenBeneath(folder_fd.get(), *relative);
  if (fd < 0 && (errno == ENOSYS || errno == EPERM)) {
    return OpenThenCheck(folder_fd.get(), folder, *relative, file);
  }
  return fd;
}

}  // namespace

SessionFile::SessionFile(const fs::path& folder, const fs::path& file) : path_(file) {
  const int fd = OpenFile(folder, file);
  if (fd < 0) {
    const int reason = errno;
    if (reason == ENOENT) Refuse(file, "no such file");
    if (reason == EXDEV) {
      Refuse(file, "refused: the path leads outside the session folder (through a symbolic link)");
    }
    if (reason == ENXIO) Refuse(file, "refused: not a regular file (a socket or a device)");
    Refuse(file, fmt::format("cannot open the file: {}", std::strerror(reason)));
  }
  FdGuard owned(fd);
  struct stat status {};
  if (::fstat(fd, &status) != 0) {
    Refuse(file, fmt::format("cannot read the file's status: {}", std::strerror(errno)));
  }
  if (!S_ISREG(status.st_mode)) {
    Refuse(file,
           fmt::format("refused: expected a regular file, found {}", FileTypeName(status.st_mode)));
  }
  // Reads of a regular file never block; clear the flag all the same.
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  size_ = static_cast<std::uintmax_t>(status.st_size);
  fd_ = owned.release();
}

SessionFile::SessionFile(SessionFile&& other) noexcept
    : fd_(std::exchange(other.fd_, -1)), path_(std::move(other.path_)), size_(other.size_) {}

SessionFile& SessionFile::operator=(SessionFile&& other) noexcept {
  std::swap(fd_, other.fd_);
  std::swap(path_, other.path_);
  std::swap(size_, other.size_);
  return *this;
}

SessionFile::~SessionFile() {
  if (fd_ >= 0) ::close(fd_);
}

int SessionFile::Release() { return std::exchange(fd_, -1); }

std::vector<unsigned char> SessionFile::ReadAll(std::uintmax_t max_bytes) const {
  if (size_ > max_bytes) {
    Refuse(path_, fmt::format("refused: the file has {} bytes, more than the {} the reducer reads",
                              size_, max_bytes));
  }
  std::vector<unsigned char> bytes(static_cast<std::size_t>(size_));
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd_, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) Refuse(path_, fmt::format("cannot read the file: {}", std::strerror(errno)));
    if (n == 0) break;  // shrank while being read: what is there is all there is
    done += static_cast<std::size_t>(n);
  }
  bytes.resize(done);
  return bytes;
}

bool IsInsideFolder(const fs::path& inner, const fs::path& folder) {
  auto i = inner.begin();
  for (auto o = folder.begin(); o != folder.end(); ++o, ++i) {
    if (o->empty()) continue;  // a trailing separator
    if (i == inner.end() || *i != *o) return false;
  }
  return true;
}

std::vector<unsigned char> ReadSessionFile(const fs::path& folder, const fs::path& file,
                                           std::uintmax_t max_bytes) {
  return SessionFile(folder, file).ReadAll(max_bytes);
}

}  // namespace impactlab
