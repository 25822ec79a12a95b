// Files named by a manifest are opened beneath the session folder, without
// following a link out and without waiting on a pipe, and only when regular:
// the check is made on the open descriptor, so swapping a file after the
// manifest was read does not get around it.
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include <catch2/catch.hpp>

#include "io/errors.h"
#include "io/manifest.h"
#include "io/session_file.h"
#include "tests/support/temp_dir.h"

namespace impactlab {
namespace {

namespace fs = std::filesystem;
using Catch::Matchers::Contains;
using testing::TempDir;

std::string Refusal(const fs::path& folder, const fs::path& file) {
  try {
    SessionFile opened(folder, file);
  } catch (const InputError& error) {
    CHECK(error.where().file == file);
    return error.what();
  }
  return "opened";
}

TEST_CASE("session_file: a regular file inside the folder is read whole") {
  TempDir dir;
  fs::create_directories(dir.path() / "runs");
  std::ofstream(dir.path() / "runs/a.csv") << "time_s,volts\n";
  CHECK(ReadSessionFile(dir.path(), dir.path() / "runs/a.csv").size() == 13);
  SECTION("through a link that stays inside") {
    fs::create_symlink("runs/a.csv", dir.path() / "link.csv");
    CHECK(ReadSessionFile(dir.path(), dir.path() / "link.csv").size() == 13);
  }
  SECTION("more than the limit is refused") {
    CHECK_THROWS_WITH(ReadSessionFile(dir.path(), dir.path() / "runs/a.csv", 12),
                      Contains("more than the 12 the reducer reads"));
  }
}

TEST_CASE("session_file: a file swapped for a link out after the check is refused") {
  TempDir dir, outside;
  std::ofstream(outside.path() / "secret") << "secret";
  std::ofstream(dir.path() / "a.jpg") << "x";
  // The manifest's check passes on the regular file...
  std::ofstream(dir.path() / "session.toml")
      << "format = 1\n[apparatus]\npendulum_length = 22\nweight = 2.23\n"
         "[[run]]\nid = \"r\"\ninitial_displacement = 0.3\nphoto = \"a.jpg\"\n";
  const Session session = ReadManifest(dir.path()).session;
  REQUIRE(session.rejected.empty());
  // ...then the file becomes a link out, directly or through its folder.
  fs::remove(dir.path() / "a.jpg");
  fs::create_symlink(outside.path() / "secret", dir.path() / "a.jpg");
  CHECK_THAT(Refusal(session.folder, *session.runs[0].photo), Contains("outside the session"));
}

TEST_CASE("session_file: a folder swapped for a link out is refused") {
  TempDir dir, outside;
  std::ofstream(outside.path() / "a.jpg") << "secret";
  fs::create_directory_symlink(outside.path(), dir.path() / "runs");
  CHECK_THAT(Refusal(dir.path(), dir.path() / "runs/a.jpg"), Contains("outside the session"));
}

TEST_CASE("session_file: a named pipe is refused at once, not waited on") {
  TempDir dir;
  REQUIRE(::mkfifo((dir.path() / "pipe.jpg").c_str(), 0600) == 0);
  const auto start = std::chrono::steady_clock::now();
  CHECK_THAT(Refusal(dir.path(), dir.path() / "pipe.jpg"), Contains("found a named pipe"));
  CHECK(std::chrono::steady_clock::now() - start < std::chrono::seconds(2));
  // Also where no folder bounds the file (a photo named on the command line).
  CHECK_THAT(Refusal("", dir.path() / "pipe.jpg"), Contains("found a named pipe"));
}

TEST_CASE("session_file: folders, devices and sockets are refused") {
  TempDir dir;
  fs::create_directories(dir.path() / "folder.jpg");
  CHECK_THAT(Refusal(dir.path(), dir.path() / "folder.jpg"), Contains("found a folder"));
  CHECK_THAT(Refusal("", "/dev/null"), Contains("found a device"));
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  sockaddr_un address{};
  address.sun_family = AF_UNIX;
  const std::string socket_path = (dir.path() / "s.jpg").string();
  if (socket_path.size() < sizeof(address.sun_path)) {
    socket_path.copy(address.sun_path, socket_path.size());
    REQUIRE(::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0);
    CHECK_THAT(Refusal(dir.path(), socket_path), Contains("refused"));
  }
  ::close(fd);
}

TEST_CASE("session_file: paths outside the folder and missing files are refused") {
  TempDir dir;
  CHECK_THAT(Refusal(dir.path(), dir.path() / "../x"), Contains("not inside the session folder"));
  CHECK_THAT(Refusal(dir.path(), "/etc/passwd"), Contains("not inside the session folder"));
  CHECK_THAT(Refusal(dir.path(), dir.path() / "missing.csv"), Contains("no such file"));
}

}  // namespace
}  // namespace impactlab
