// A small typed view of an HDF5 results file: datasets addressed by slash
// paths ("/runs/0.234/contact_time"), intermediate groups created on demand,
// every numeric dataset written with its `units` attribute (results-layout.md).
// The HDF5 library stays private to io/.
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace impactlab {

// The HDF5 library in use (linked statically: the one compiled against), e.g. "1.10.8".
std::string Hdf5Version();

class Hdf5File {
 public:
  // Opens read-only. Throws InputError naming the file. (Files are written
  // only through WriteHdf5Atomically.)
  static Hdf5File OpenReadOnly(const std::filesystem::path& path);

  Hdf5File(Hdf5File&&) noexcept;
  Hdf5File& operator=(Hdf5File&&) noexcept;
  ~Hdf5File();

  const std::filesystem::path& path() const;

  // Writing. `units` is mandatory for numbers ("1" for dimensionless).
  void WriteScalar(const std::string& dataset, double value, std::string_view units);
  void WriteVector(const std::string& dataset, const std::vector<double>& values,
                   std::string_view units);
  void WriteIntegers(const std::string& dataset, const std::vector<long long>& values);
  void WriteStrings(const std::string& dataset, const std::vector<std::string>& values);
  // Raw bytes (an encoded image, say) as a 1-D uint8 dataset.
  void WriteBytes(const std::string& dataset, const std::vector<unsigned char>& bytes);
  void CreateGroup(const std::string& group);
  void SetAttribute(const std::string& object, const std::string& name, const std::string& value);
  void SetAttribute(const std::string& object, const std::string& name, long long value);
  void SetAttribute(const std::string& object, const std::string& name,
                    const std::vector<long long>& values);

  // Reading. Throws InputError naming the file and the object when missing.
  bool Exists(const std::string& object) const;
  std::vector<std::string> Children(const std::string& group) const;  // in creation order
  double ReadScalar(const std::string& dataset) const;
  std::vector<double> ReadVector(const std::string& dataset) const;
  std::vector<long long> ReadIntegers(const std::string& dataset) const;
  std::vector<std::string> ReadStrings(const std::string& dataset) const;
  std::vector<unsigned char> ReadBytes(const std::string& dataset) const;
  std::string ReadStringAttribute(const std::string& object, const std::string& name) const;
  long long ReadIntegerAttribute(const std::string& object, const std::string& name) const;
  std::vector<long long> ReadIntegerArrayAttribute(const std::string& object,
                                                   const std::string& name) const;
  bool HasAttribute(const std::string& object, const std::string& name) const;
  // The names of `object`'s attributes, in creation order (by name when the
  // file does not track it).
  std::vector<std::string> AttributeNames(const std::string& object) const;
  bool IsGroup(const std::string& object) const;
  bool IsNumericDataset(const std::string& object) const;  // float or integer elements

  // Optional reads: nullopt when the object is absent.
  std::optional<double> ReadScalarIfPresent(const std::string& dataset) const;

 private:
  struct Impl;
  explicit Hdf5File(std::unique_ptr<Impl> impl);
  // A new file held in memory (HDF5's core driver, no backing store); `path`
  // names it in messages.
  static Hdf5File CreateInMemory(const std::filesystem::path& path);
  friend void WriteHdf5Atomically(const std::filesystem::path& path,
                                  const std::function<void(Hdf5File&)>& write);
  // The file's HDF5 identifier (a hid_t), for io/hdf5_extras.h.
  std::int64_t NativeId() const;
  friend class Hdf5Extras;
  std::unique_ptr<Impl> impl_;
};

// Writes `path` atomically: `write` fills a file held in memory, which is
// then closed (every HDF5 status checked) and its bytes written by
// WriteFileAtomically (io/atomic_file.h): a temporary beside `path`, synced
// and renamed over it. HDF5 itself never touches the disk, so a full disk or
// a size limit can only fail our own checked write(). If anything fails,
// InputError names `path`, no temporary is left and an earlier file at `path`
// is byte-identical.
void WriteHdf5Atomically(const std::filesystem::path& path,
                         const std::function<void(Hdf5File&)>& write);

// Joins path components with '/', e.g. JoinPath({"runs", id, "rebounds"}).
std::string JoinPath(std::initializer_list<std::string_view> parts);

}  // namespace impactlab
