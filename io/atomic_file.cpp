#include "io/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "io/errors.h"
#include "io/session_file.h"

namespace impactlab {
namespace fs = std::filesystem;
namespace {

// The temporaries being written right now. This is global state on purpose:
// a signal handler can reach nothing else. Paths are kept in fixed buffers
// and slots are claimed with lock-free atomics, so the handler can remove the
// files with unlink() alone (async-signal-safe: no allocation, no locks).
constexpr int kSlots = 8;  // more than the writes one process has open at once
constexpr std::size_t kMaxPath = 4096;
enum SlotState : int { kFree = 0, kFilling = 1, kRegistered = 2 };
struct Slot {
  std::atomic<int> state{kFree};
  char path[kMaxPath];
};
static_assert(std::atomic<int>::is_always_lock_free);
Slot g_slots[kSlots];

void RemoveRegisteredTemporaries() {
  for (Slot& slot : g_slots) {
    if (slot.state.load(std::memory_order_acquire) == kRegistered) ::unlink(slot.path);
  }
}

extern "C" void RemoveTemporariesAndReraise(int signal_number) {
  const int saved_errno = errno;
  RemoveRegisteredTemporaries();
  // SA_RESETHAND restored the default action; the signal is blocked until
  // this handler returns, then it ends the process as if never caught.
  ::raise(signal_number);
  errno = saved_errno;
}

extern "C" void RemoveTemporariesAtExit() { RemoveRegisteredTemporaries(); }

// One temporary file's registration: removed (and forgotten) on destruction
// unless Keep() was called after it was renamed into place.
class RegisteredTemporary {
 public:
  explicit RegisteredTemporary(const fs::path& path) : path_(path) {
    const std::string& text = path_.native();
    if (text.size() >= kMaxPath) return;  // not registered: only signal cleanup is lost
    for (int i = 0; i < kSlots; ++i) {
      int expected = kFree;
      if (g_slots[i].state.compare_exchange_strong(expected, kFilling)) {
        std::memcpy(g_slots[i].path, text.c_str(), text.size() + 1);
        g_slots[i].state.store(kRegistered, std::memory_order_release);
        slot_ = i;
        return;
      }
    }
  }
  RegisteredTemporary(const RegisteredTemporary&) = delete;
  RegisteredTemporary& operator=(const RegisteredTemporary&) = delete;
  ~RegisteredTemporary() {
    if (!kept_) ::unlink(path_.c_str());
    if (slot_ >= 0) g_slots[slot_].state.store(kFree, std::memory_order_release);
  }
  void Keep() { kept_ = true; }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  int slot_ = -1;
  bool kept_ = false;
};

// Closes a descriptor on error paths (the success path closes it checked).
class Descriptor {
 public:
  explicit Descriptor(int fd) : fd_(fd) {}
  Descriptor(const Descriptor&) = delete;
  Descriptor& operator=(const Descriptor&) = delete;
  ~Descriptor() {
    if (fd_ >= 0) ::close(fd_);
  }
  int get() const { return fd_; }
  int Close() {
    const int status = ::close(fd_);
    fd_ = -1;
    return status;
  }

 private:
  int fd_;
};

fs::path FolderOf(const fs::path& path) {
  const fs::path parent = path.parent_path();
  return parent.empty() ? fs::path(".") : parent;
}

// The pid of `name` when it reads "<prefix><digits>".
std::optional<pid_t> TemporaryPid(const std::string& name, const std::string& prefix) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) {
    return std::nullopt;
  }
  const std::string digits = name.substr(prefix.size());
  if (digits.size() > 9 ||
      !std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) {
    return std::nullopt;
  }
  const long pid = std::stol(digits);
  if (pid <= 0) return std::nullopt;
  return static_cast<pid_t>(pid);
}

}  // namespace

void CheckOutputPath(const fs::path& output, const fs::path& session_folder) {
  const auto refuse = [&](const std::string& problem) {
    throw InputError({output, "", std::nullopt}, problem);
  };
  if (output.empty()) refuse("the output file name is empty");
  std::error_code ec;
  const fs::file_status status = fs::status(output, ec);  // follows symbolic links
  if (fs::is_directory(status)) {
    refuse("is a folder; give a file name for the output, e.g. " +
           (output / "results.h5").string());
  }
  if (fs::exists(status) && !fs::is_regular_file(status)) {
    refuse("exists and is not a regular file; give another output file");
  }
  const fs::path folder = FolderOf(output);
  const fs::file_status folder_status = fs::status(folder, ec);
  if (!fs::exists(folder_status)) {
    refuse(fmt::format("cannot write the output: the folder {} does not exist", folder.string()));
  }
  if (!fs::is_directory(folder_status)) {
    refuse(fmt::format("cannot write the output: {} is not a folder", folder.string()));
  }
  if (!session_folder.empty() && fs::is_directory(session_folder, ec)) {
    const fs::path session = fs::canonical(session_folder, ec);
    if (ec) return;  // unreadable: reading the manifest reports it
    const fs::path target = fs::weakly_canonical(fs::absolute(output), ec);
    if (!ec && IsInsideFolder(target, session)) {
      refuse(fmt::format(
          "lies inside the session folder {}; impactlab never writes into a session (it is "
          "the lab's record), so write the output elsewhere",
          session_folder.string()));
    }
  }
}

fs::path TemporaryPathFor(const fs::path& path) {
  fs::path temporary = path;
  temporary += fmt::format(".tmp-{}", ::getpid());
  return temporary;
}

int RemoveStaleTemporaries(const fs::path& path) {
  const std::string prefix = path.filename().string() + ".tmp-";
  int removed = 0;
  std::error_code ec;
  fs::directory_iterator it(FolderOf(path), ec);
  for (; !ec && it != fs::directory_iterator(); it.increment(ec)) {
    const std::optional<pid_t> pid = TemporaryPid(it->path().filename().string(), prefix);
    if (!pid || *pid == ::getpid()) continue;
    if (::kill(*pid, 0) == -1 && errno == ESRCH) {
      std::error_code ignored;
      if (fs::remove(it->path(), ignored)) ++removed;
    }
  }
  return removed;
}

void WriteFileAtomically(const fs::path& path, std::string_view bytes) {
  const auto fail = [&](const std::string& what, int error) {
    throw InputError({path, "", std::nullopt},
                     fmt::format("cannot write the file ({}: {}); {}", what, std::strerror(error),
                                 "an earlier file of that name is left as it was"));
  };
  // Through a symbolic link: replace the file it points to, keep the link.
  fs::path target = path;
  std::error_code ec;
  if (fs::is_symlink(path, ec)) {
    target = fs::weakly_canonical(path, ec);
    if (ec) fail("resolving the symbolic link", ec.value());
  }
  RemoveStaleTemporaries(target);

  RegisteredTemporary temporary(TemporaryPathFor(target));
  ::unlink(temporary.path().c_str());  // a leftover of a dead process that had our pid
  Descriptor fd(::open(temporary.path().c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666));
  if (fd.get() < 0) fail("creating a temporary file beside it", errno);
  const char* data = bytes.data();
  std::size_t left = bytes.size();
  while (left > 0) {
    const ssize_t written = ::write(fd.get(), data, std::min<std::size_t>(left, 1u << 30));
    if (written < 0) {
      if (errno == EINTR) continue;
      fail("writing", errno);
    }
    if (written == 0) fail("writing", EIO);
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  if (::fsync(fd.get()) != 0) fail("syncing to disk", errno);
  if (fd.Close() != 0) fail("closing", errno);
  if (::rename(temporary.path().c_str(), target.c_str()) != 0) fail("renaming into place", errno);
  temporary.Keep();

  // Make the rename itself durable. The new file is in place already, so a
  // failure here only means it might not survive a crash: say so.
  Descriptor folder(::open(FolderOf(target).c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC));
  if (folder.get() < 0 || ::fsync(folder.get()) != 0) {
    throw InputError({path, "", std::nullopt},
                     fmt::format("the new file is in place, but its folder could not be synced "
                                 "to disk ({}); it may not survive a crash",
                                 std::strerror(errno)));
  }
}

void InstallTemporaryFileCleanup() {
  static std::atomic<bool> installed{false};
  if (installed.exchange(true)) return;
  std::atexit(RemoveTemporariesAtExit);
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    struct sigaction previous {};
    if (::sigaction(signal_number, nullptr, &previous) != 0) continue;
    if (previous.sa_handler == SIG_IGN) continue;  // nohup, background jobs
    struct sigaction action {};
    action.sa_handler = RemoveTemporariesAndReraise;
    sigemptyset(&action.sa_mask);
    action.sa_flags = SA_RESETHAND;
    ::sigaction(signal_number, &action, nullptr);
  }
}

}  // namespace impactlab
