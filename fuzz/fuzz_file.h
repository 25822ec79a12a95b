// Helpers for fuzz targets whose parser reads a file: the input written to a
// per-process temporary file.
#pragma once

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace impactlab::fuzz {

// `data` written to a file named `name` (extension matters to some readers)
// in a folder of this process's own; the same path every call.
inline std::filesystem::path WriteInput(const uint8_t* data, std::size_t size,
                                        const std::string& name) {
  static const std::filesystem::path folder = [] {
    const auto dir =
        std::filesystem::temp_directory_path() / ("impactlab-fuzz-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    return dir;
  }();
  const std::filesystem::path path = folder / name;
  std::ofstream(path, std::ios::binary | std::ios::trunc)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

}  // namespace impactlab::fuzz
