// Tests of atomic output files: a failed write (a throwing writer, a file size
// limit) leaves the earlier file byte-identical and no temporary; stale
// temporaries of dead processes are removed; unwritable or forbidden outputs
// are refused naming the output.
#include <signal.h>
#include <sys/inotify.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

#include "io/atomic_file.h"
#include "io/errors.h"
#include "io/hdf5_file.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;

std::string ReadAll(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void WriteAll(const fs::path& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

std::vector<std::string> Names(const fs::path& folder) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(folder)) {
    names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

// The pid of a child that has exited and been reaped: no such process now.
pid_t DeadPid() {
  const pid_t child = ::fork();
  if (child == 0) ::_exit(0);
  int status = 0;
  ::waitpid(child, &status, 0);
  return child;
}

void WriteSmallResults(Hdf5File& file) {
  file.WriteScalar("/runs/a/contact_time", 353.35e-6, "s");
  file.SetAttribute("/", "producer", "test");
}

// Limits this process's file size (as `ulimit -f` does), with SIGXFSZ
// ignored so that write() fails with EFBIG; restored on destruction.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    old_handler_ = ::signal(SIGXFSZ, SIG_IGN);
    rlimit limit = saved_;
    limit.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &limit);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    ::signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit saved_{};
  sighandler_t old_handler_;
};

TEST_CASE("atomic_file: an HDF5 file written atomically reads back") {
  testing::TempDir dir;
  const fs::path path = dir.path() / "results.h5";
  WriteHdf5Atomically(path, WriteSmallResults);
  const Hdf5File file = Hdf5File::OpenReadOnly(path);
  CHECK(file.ReadScalar("/runs/a/contact_time") == 353.35e-6);
  CHECK(file.ReadStringAttribute("/runs/a/contact_time", "units") == "s");
  CHECK(file.ReadStringAttribute("/", "producer") == "test");
  CHECK(Names(dir.path()) == std::vector<std::string>{"results.h5"});
}

TEST_CASE("atomic_file: an HDF5 file written over an earlier one never opens the earlier one") {
  // HDF5 opens a new file's name before creating it, and its in-memory
  // driver read all of an earlier file there into memory (a second reduce to
  // the same output read the first one's results, to no end).
  testing::TempDir dir;
  const fs::path path = dir.path() / "results.h5";
  WriteHdf5Atomically(path, WriteSmallResults);
  const int watch = ::inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  REQUIRE(watch >= 0);
  REQUIRE(::inotify_add_watch(watch, path.c_str(), IN_OPEN | IN_ACCESS) >= 0);
  WriteHdf5Atomically(path, WriteSmallResults);
  alignas(inotify_event) char events[4096];
  const ssize_t got = ::read(watch, events, sizeof events);
  std::vector<std::uint32_t> opened_or_read;
  for (ssize_t at = 0; at < got;) {
    const auto* event = reinterpret_cast<const inotify_event*>(events + at);
    if (event->mask & (IN_OPEN | IN_ACCESS)) opened_or_read.push_back(event->mask);
    at += static_cast<ssize_t>(sizeof(inotify_event) + event->len);
  }
  ::close(watch);
  CHECK(opened_or_read.empty());
  CHECK(Hdf5File::OpenReadOnly(path).ReadScalar("/runs/a/contact_time") == 353.35e-6);
}

TEST_CASE("atomic_file: a failure inside the writer leaves the old file and no temporary") {
  testing::TempDir dir;
  const fs::path path = dir.path() / "results.h5";
  WriteHdf5Atomically(path, WriteSmallResults);
  const std::string before = ReadAll(path);
  CHECK_THROWS_AS(WriteHdf5Atomically(path,
                                      [](Hdf5File& file) {
                                        file.WriteScalar("/x", 1.0, "m");
                                        throw std::runtime_error("writer failed");
                                      }),
                  std::runtime_error);
  // An HDF5 error in the middle (a dataset written twice) names the output.
  CHECK_THROWS_WITH(WriteHdf5Atomically(path,
                                        [](Hdf5File& file) {
                                          file.WriteScalar("/x", 1.0, "m");
                                          file.WriteScalar("/x", 2.0, "m");
                                        }),
                    Contains(path.string()));
  CHECK(ReadAll(path) == before);
  CHECK(Names(dir.path()) == std::vector<std::string>{"results.h5"});
}

TEST_CASE("atomic_file: a write beyond the file size limit fails, naming the output") {
  testing::TempDir dir;
  const fs::path path = dir.path() / "report.md";
  WriteAll(path, "the good old report\n");
  const std::string big(64 * 1024, 'x');
  {
    const FileSizeLimit limit(16 * 1024);
    CHECK_THROWS_WITH(WriteFileAtomically(path, big),
                      Contains(path.string()) && Contains("File too large") && !Contains(".tmp-"));
  }
  CHECK(ReadAll(path) == "the good old report\n");
  CHECK(Names(dir.path()) == std::vector<std::string>{"report.md"});
}

TEST_CASE("atomic_file: an HDF5 write beyond the file size limit leaves the old file") {
  testing::TempDir dir;
  const fs::path path = dir.path() / "results.h5";
  WriteHdf5Atomically(path, WriteSmallResults);
  const std::string before = ReadAll(path);
  const auto write_big = [](Hdf5File& file) {
    file.WriteVector("/big", std::vector<double>(100000, 1.0), "m");
  };
  {
    const FileSizeLimit limit(64 * 1024);
    CHECK_THROWS_AS(WriteHdf5Atomically(path, write_big), InputError);
  }
  CHECK(ReadAll(path) == before);
  CHECK(Names(dir.path()) == std::vector<std::string>{"results.h5"});
  WriteHdf5Atomically(path, write_big);  // and without the limit it works
  CHECK(Hdf5File::OpenReadOnly(path).ReadVector("/big").size() == 100000);
}

TEST_CASE(
    "atomic_file: SIGTERM or SIGINT during a write removes the temporary, keeps the old file") {
  const int signal_number = GENERATE(SIGTERM, SIGINT);
  testing::TempDir dir;
  const fs::path path = dir.path() / "results.h5";
  WriteAll(path, "old");
  const pid_t child = ::fork();
  if (child == 0) {
    try {
      InstallTemporaryFileCleanup();
      // Big enough that the write (and its fsync) outlasts the parent's kill.
      WriteFileAtomically(path, std::string(std::size_t{64} << 20, 'x'));
    } catch (...) {
      ::_exit(2);
    }
    ::_exit(0);
  }
  const fs::path temporary = dir.path() / ("results.h5.tmp-" + std::to_string(child));
  for (int i = 0; i < 20000 && !fs::exists(temporary); ++i) ::usleep(100);
  CHECK(fs::exists(temporary));
  ::kill(child, signal_number);
  int status = 0;
  ::waitpid(child, &status, 0);
  REQUIRE(WIFSIGNALED(status));  // killed by the re-raised signal, not exited
  CHECK(WTERMSIG(status) == signal_number);
  CHECK(ReadAll(path) == "old");
  CHECK(Names(dir.path()) == std::vector<std::string>{"results.h5"});
}

TEST_CASE("atomic_file: stale temporaries of dead processes are removed, live ones kept") {
  testing::TempDir dir;
  const fs::path path = dir.path() / "results.h5";
  const std::string dead = "results.h5.tmp-" + std::to_string(DeadPid());
  const std::string mine = "results.h5.tmp-" + std::to_string(::getpid());
  const std::string parent = "results.h5.tmp-" + std::to_string(::getppid());
  const std::string other_output = "other.h5.tmp-" + std::to_string(DeadPid());
  const std::string not_a_pid = "results.h5.tmp-12ab";
  for (const std::string& name : {dead, mine, parent, other_output, not_a_pid}) {
    WriteAll(dir.path() / name, "partial");
  }
  CHECK(RemoveStaleTemporaries(path) == 1);
  std::vector<std::string> kept = {mine, parent, other_output, not_a_pid};
  std::sort(kept.begin(), kept.end());
  CHECK(Names(dir.path()) == kept);
}

TEST_CASE("atomic_file: the next write of an output removes its stale temporary") {
  testing::TempDir dir;
  const fs::path path = dir.path() / "results.h5";
  WriteAll(dir.path() / ("results.h5.tmp-" + std::to_string(DeadPid())), "partial");
  WriteFileAtomically(path, "new");
  CHECK(ReadAll(path) == "new");
  CHECK(Names(dir.path()) == std::vector<std::string>{"results.h5"});
}

TEST_CASE("atomic_file: through a symbolic link the target is replaced, the link kept") {
  testing::TempDir dir;
  fs::create_directory(dir.path() / "data");
  WriteAll(dir.path() / "data" / "r.md", "old");
  fs::create_symlink(dir.path() / "data" / "r.md", dir.path() / "link.md");
  WriteFileAtomically(dir.path() / "link.md", "new");
  CHECK(fs::is_symlink(dir.path() / "link.md"));
  CHECK(ReadAll(dir.path() / "data" / "r.md") == "new");
  CHECK(Names(dir.path() / "data") == std::vector<std::string>{"r.md"});
}

TEST_CASE("atomic_file: outputs that cannot or must not be written are refused") {
  testing::TempDir dir;
  const fs::path session = dir.path() / "session";
  fs::create_directories(session / "photos");
  WriteAll(session / "session.toml", "title = \"t\"\n");

  CHECK_NOTHROW(CheckOutputPath(dir.path() / "results.h5", session));
  CHECK_NOTHROW(CheckOutputPath(dir.path() / "session.toml", session));  // beside, not inside

  const fs::path folder = dir.path() / "out";
  fs::create_directory(folder);
  CHECK_THROWS_WITH(CheckOutputPath(folder, session),
                    Contains(folder.string()) && Contains("is a folder"));

  const fs::path missing = dir.path() / "nodir" / "x.h5";
  CHECK_THROWS_WITH(CheckOutputPath(missing, session),
                    Contains(missing.string()) && Contains("does not exist") && !Contains(".tmp-"));

  for (const fs::path& inside :
       {session / "session.toml", session / "photos" / "r.h5", session / "new.h5",
        dir.path() / "out" / ".." / "session" / "r.h5"}) {
    CHECK_THROWS_WITH(CheckOutputPath(inside, session),
                      Contains(inside.string()) && Contains("inside the session folder"));
  }
  // A link to the session is seen through.
  fs::create_directory_symlink(session, dir.path() / "alias");
  CHECK_THROWS_WITH(CheckOutputPath(dir.path() / "alias" / "r.h5", session),
                    Contains("inside the session folder"));
  // Without a session, only the file checks apply.
  CHECK_NOTHROW(CheckOutputPath(session / "r.h5"));
  CHECK_THROWS_WITH(CheckOutputPath(""), Contains("empty"));
}

TEST_CASE("atomic_file: the temporary is named after the output and this process") {
  CHECK(TemporaryPathFor("/a/results.h5") ==
        fs::path("/a/results.h5.tmp-" + std::to_string(::getpid())));
}

}  // namespace
}  // namespace impactlab
