#include "io/hdf5_file.h"

#include <hdf5.h>
#include <unistd.h>

#include <fmt/format.h>

#include "io/errors.h"

namespace impactlab {
namespace {

// Owns one HDF5 identifier and closes it with the matching function.
class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Handle(Handle&& other) noexcept : id_(other.id_), close_(other.close_) { other.id_ = -1; }
  Handle& operator=(Handle&& other) noexcept {
    std::swap(id_, other.id_);
    std::swap(close_, other.close_);
    return *this;
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  ~Handle() {
    if (id_ >= 0 && close_ != nullptr) close_(id_);
  }
  hid_t get() const { return id_; }
  bool valid() const { return id_ >= 0; }

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

// HDF5 prints its error stack to stderr by default; we report our own errors.
void SilenceHdf5ErrorStack() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

Handle VariableStringType() {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.get(), H5T_VARIABLE);
  H5Tset_cset(type.get(), H5T_CSET_UTF8);
  return type;
}

// Groups remember creation order, so runs list in manifest order.
Handle OrderedGroupCreation() {
  Handle plist(H5Pcreate(H5P_GROUP_CREATE), H5Pclose);
  H5Pset_link_creation_order(plist.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED);
  return plist;
}

Handle IntermediateGroups() {
  Handle plist(H5Pcreate(H5P_LINK_CREATE), H5Pclose);
  H5Pset_create_intermediate_group(plist.get(), 1);
  return plist;
}

}  // namespace

struct Hdf5File::Impl {
  std::filesystem::path path;
  Handle file;

  [[noreturn]] void Fail(const std::string& object, const std::string& problem) const {
    throw InputError({path, object, std::nullopt}, problem);
  }

  void Check(herr_t status, const std::string& object, const char* what) const {
    if (status < 0) Fail(object, fmt::format("HDF5 could not {}", what));
  }

  // Makes every missing group on the way to `object` (with creation order).
  void EnsureParentGroups(const std::string& object) {
    std::size_t pos = 1;
    while ((pos = object.find('/', pos)) != std::string::npos) {
      const std::string group = object.substr(0, pos);
      if (H5Lexists(file.get(), group.c_str(), H5P_DEFAULT) <= 0) {
        const Handle plist = OrderedGroupCreation();
        Handle g(H5Gcreate2(file.get(), group.c_str(), H5P_DEFAULT, plist.get(), H5P_DEFAULT),
                 H5Gclose);
        if (!g.valid()) Fail(group, "HDF5 could not create the group");
      }
      ++pos;
    }
  }

  Handle CreateDataset(const std::string& name, hid_t type, const std::vector<hsize_t>& dims) {
    EnsureParentGroups(name);
    Handle space(dims.empty()
                     ? H5Screate(H5S_SCALAR)
                     : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
                 H5Sclose);
    const Handle links = IntermediateGroups();
    Handle dset(H5Dcreate2(file.get(), name.c_str(), type, space.get(), links.get(), H5P_DEFAULT,
                           H5P_DEFAULT),
                H5Dclose);
    if (!dset.valid()) Fail(name, "HDF5 could not create the dataset (does it exist already?)");
    return dset;
  }

  Handle OpenObject(const std::string& name) const {
    if (H5Lexists(file.get(), name.c_str(), H5P_DEFAULT) <= 0 && name != "/") {
      Fail(name, "not found in the results file");
    }
    Handle obj(H5Oopen(file.get(), name.c_str(), H5P_DEFAULT), H5Oclose);
    if (!obj.valid()) Fail(name, "HDF5 could not open the object");
    return obj;
  }

  Handle OpenDataset(const std::string& name) const {
    OpenObject(name);  // for the "not found" message
    Handle dset(H5Dopen2(file.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
    if (!dset.valid()) Fail(name, "is not a dataset");
    return dset;
  }

  hssize_t ElementCount(const Handle& dset) const {
    Handle space(H5Dget_space(dset.get()), H5Sclose);
    return H5Sget_simple_extent_npoints(space.get());
  }

  void WriteStringAttribute(hid_t obj, const std::string& object, const std::string& name,
                            const std::string& value) {
    const Handle type = VariableStringType();
    Handle space(H5Screate(H5S_SCALAR), H5Sclose);
    if (H5Aexists(obj, name.c_str()) > 0) H5Adelete(obj, name.c_str());
    Handle attr(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
                H5Aclose);
    const char* text = value.c_str();
    Check(H5Awrite(attr.get(), type.get(), &text), object, "write an attribute");
  }

  void WriteIntegerAttribute(hid_t obj, const std::string& object, const std::string& name,
                             const std::vector<long long>& values, bool scalar) {
    const hsize_t n = values.size();
    Handle space(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose);
    if (H5Aexists(obj, name.c_str()) > 0) H5Adelete(obj, name.c_str());
    Handle attr(
        H5Acreate2(obj, name.c_str(), H5T_NATIVE_LLONG, space.get(), H5P_DEFAULT, H5P_DEFAULT),
        H5Aclose);
    Check(H5Awrite(attr.get(), H5T_NATIVE_LLONG, values.data()), object, "write an attribute");
  }

  Handle OpenAttribute(const std::string& object, const std::string& name) const {
    const Handle obj = OpenObject(object);
    if (H5Aexists(obj.get(), name.c_str()) <= 0) {
      Fail(object, fmt::format("has no attribute '{}'", name));
    }
    return Handle(H5Aopen(obj.get(), name.c_str(), H5P_DEFAULT), H5Aclose);
  }
};

Hdf5File::Hdf5File(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Hdf5File::Hdf5File(Hdf5File&&) noexcept = default;
Hdf5File& Hdf5File::operator=(Hdf5File&&) noexcept = default;
Hdf5File::~Hdf5File() = default;

Hdf5File Hdf5File::Create(const std::filesystem::path& path) {
  SilenceHdf5ErrorStack();
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  // The root group remembers creation order too.
  Handle plist(H5Pcreate(H5P_FILE_CREATE), H5Pclose);
  H5Pset_link_creation_order(plist.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED);
  impl->file = Handle(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, plist.get(), H5P_DEFAULT), H5Fclose);
  if (!impl->file.valid()) {
    throw InputError({path, "", std::nullopt}, "cannot create the results file");
  }
  return Hdf5File(std::move(impl));
}

Hdf5File Hdf5File::OpenReadOnly(const std::filesystem::path& path) {
  SilenceHdf5ErrorStack();
  if (!std::filesystem::exists(path)) {
    throw InputError({path, "", std::nullopt}, "no such results file");
  }
  if (H5Fis_hdf5(path.c_str()) <= 0) {
    throw InputError({path, "", std::nullopt}, "not an HDF5 file");
  }
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->file = Handle(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!impl->file.valid()) {
    throw InputError({path, "", std::nullopt}, "cannot open the results file");
  }
  return Hdf5File(std::move(impl));
}

const std::filesystem::path& Hdf5File::path() const { return impl_->path; }

void Hdf5File::WriteScalar(const std::string& name, double value, std::string_view units) {
  const Handle dset = impl_->CreateDataset(name, H5T_IEEE_F64LE, {});
  impl_->Check(H5Dwrite(dset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &value), name,
               "write the dataset");
  impl_->WriteStringAttribute(dset.get(), name, "units", std::string(units));
}

void Hdf5File::WriteVector(const std::string& name, const std::vector<double>& values,
                           std::string_view units) {
  const Handle dset = impl_->CreateDataset(name, H5T_IEEE_F64LE, {values.size()});
  if (!values.empty()) {
    impl_->Check(
        H5Dwrite(dset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name,
        "write the dataset");
  }
  impl_->WriteStringAttribute(dset.get(), name, "units", std::string(units));
}

void Hdf5File::WriteIntegers(const std::string& name, const std::vector<long long>& values) {
  const Handle dset = impl_->CreateDataset(name, H5T_STD_I64LE, {values.size()});
  if (!values.empty()) {
    impl_->Check(
        H5Dwrite(dset.get(), H5T_NATIVE_LLONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name,
        "write the dataset");
  }
}

void Hdf5File::WriteStrings(const std::string& name, const std::vector<std::string>& values) {
  const Handle type = VariableStringType();
  const Handle dset = impl_->CreateDataset(name, type.get(), {values.size()});
  std::vector<const char*> text;
  for (const std::string& v : values) text.push_back(v.c_str());
  if (!text.empty()) {
    impl_->Check(H5Dwrite(dset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data()), name,
                 "write the dataset");
  }
}

void Hdf5File::WriteBytes(const std::string& name, const std::vector<unsigned char>& bytes) {
  const Handle dset = impl_->CreateDataset(name, H5T_STD_U8LE, {bytes.size()});
  if (!bytes.empty()) {
    impl_->Check(
        H5Dwrite(dset.get(), H5T_NATIVE_UCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data()), name,
        "write the dataset");
  }
}

std::vector<unsigned char> Hdf5File::ReadBytes(const std::string& name) const {
  const Handle dset = impl_->OpenDataset(name);
  std::vector<unsigned char> bytes(static_cast<std::size_t>(impl_->ElementCount(dset)));
  if (!bytes.empty()) {
    impl_->Check(H5Dread(dset.get(), H5T_NATIVE_UCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data()),
                 name, "read the dataset");
  }
  return bytes;
}

void Hdf5File::CreateGroup(const std::string& group) {
  if (Exists(group)) return;
  impl_->EnsureParentGroups(group + "/");
}

void Hdf5File::SetAttribute(const std::string& object, const std::string& name,
                            const std::string& value) {
  const Handle obj = impl_->OpenObject(object);
  impl_->WriteStringAttribute(obj.get(), object, name, value);
}

void Hdf5File::SetAttribute(const std::string& object, const std::string& name, long long value) {
  const Handle obj = impl_->OpenObject(object);
  impl_->WriteIntegerAttribute(obj.get(), object, name, {value}, /*scalar=*/true);
}

void Hdf5File::SetAttribute(const std::string& object, const std::string& name,
                            const std::vector<long long>& values) {
  const Handle obj = impl_->OpenObject(object);
  impl_->WriteIntegerAttribute(obj.get(), object, name, values, /*scalar=*/false);
}

bool Hdf5File::Exists(const std::string& object) const {
  if (object == "/") return true;
  // H5Lexists needs every parent to exist: walk down the path.
  std::size_t pos = 1;
  while (true) {
    pos = object.find('/', pos);
    const std::string prefix = object.substr(0, pos);
    if (H5Lexists(impl_->file.get(), prefix.c_str(), H5P_DEFAULT) <= 0) return false;
    if (pos == std::string::npos) return true;
    ++pos;
  }
}

std::vector<std::string> Hdf5File::Children(const std::string& group) const {
  const Handle obj = impl_->OpenObject(group);
  std::vector<std::string> names;
  const auto collect = [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
    static_cast<std::vector<std::string>*>(data)->emplace_back(name);
    return 0;
  };
  hsize_t index = 0;
  if (H5Literate(obj.get(), H5_INDEX_CRT_ORDER, H5_ITER_INC, &index, collect, &names) < 0) {
    names.clear();  // a group written without creation order: fall back to names
    index = 0;
    H5Literate(obj.get(), H5_INDEX_NAME, H5_ITER_INC, &index, collect, &names);
  }
  return names;
}

double Hdf5File::ReadScalar(const std::string& name) const {
  const Handle dset = impl_->OpenDataset(name);
  if (impl_->ElementCount(dset) != 1) impl_->Fail(name, "expected a scalar dataset");
  double value = 0.0;
  impl_->Check(H5Dread(dset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &value), name,
               "read the dataset");
  return value;
}

std::optional<double> Hdf5File::ReadScalarIfPresent(const std::string& name) const {
  if (!Exists(name)) return std::nullopt;
  return ReadScalar(name);
}

std::vector<double> Hdf5File::ReadVector(const std::string& name) const {
  const Handle dset = impl_->OpenDataset(name);
  std::vector<double> values(static_cast<std::size_t>(impl_->ElementCount(dset)));
  if (!values.empty()) {
    impl_->Check(
        H5Dread(dset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name,
        "read the dataset");
  }
  return values;
}

std::vector<long long> Hdf5File::ReadIntegers(const std::string& name) const {
  const Handle dset = impl_->OpenDataset(name);
  std::vector<long long> values(static_cast<std::size_t>(impl_->ElementCount(dset)));
  if (!values.empty()) {
    impl_->Check(
        H5Dread(dset.get(), H5T_NATIVE_LLONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name,
        "read the dataset");
  }
  return values;
}

std::vector<std::string> Hdf5File::ReadStrings(const std::string& name) const {
  const Handle dset = impl_->OpenDataset(name);
  const Handle type = VariableStringType();
  std::vector<char*> text(static_cast<std::size_t>(impl_->ElementCount(dset)), nullptr);
  std::vector<std::string> values;
  if (text.empty()) return values;
  impl_->Check(H5Dread(dset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data()), name,
               "read the dataset");
  for (char* t : text) values.emplace_back(t != nullptr ? t : "");
  Handle space(H5Dget_space(dset.get()), H5Sclose);
  H5Dvlen_reclaim(type.get(), space.get(), H5P_DEFAULT, text.data());
  return values;
}

std::string Hdf5File::ReadStringAttribute(const std::string& object,
                                          const std::string& name) const {
  const Handle attr = impl_->OpenAttribute(object, name);
  const Handle type = VariableStringType();
  char* text = nullptr;
  impl_->Check(H5Aread(attr.get(), type.get(), &text), object, "read an attribute");
  std::string value = text != nullptr ? text : "";
  H5free_memory(text);
  return value;
}

long long Hdf5File::ReadIntegerAttribute(const std::string& object, const std::string& name) const {
  const std::vector<long long> values = ReadIntegerArrayAttribute(object, name);
  if (values.size() != 1) impl_->Fail(object, fmt::format("attribute '{}' is not a scalar", name));
  return values.front();
}

std::vector<long long> Hdf5File::ReadIntegerArrayAttribute(const std::string& object,
                                                           const std::string& name) const {
  const Handle attr = impl_->OpenAttribute(object, name);
  Handle space(H5Aget_space(attr.get()), H5Sclose);
  std::vector<long long> values(
      static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.get())));
  impl_->Check(H5Aread(attr.get(), H5T_NATIVE_LLONG, values.data()), object, "read an attribute");
  return values;
}

bool Hdf5File::HasAttribute(const std::string& object, const std::string& name) const {
  if (!Exists(object)) return false;
  const Handle obj = impl_->OpenObject(object);
  return H5Aexists(obj.get(), name.c_str()) > 0;
}

bool Hdf5File::IsGroup(const std::string& object) const {
  if (!Exists(object)) return false;
  H5O_info_t info;
  const Handle obj = impl_->OpenObject(object);
  return H5Oget_info2(obj.get(), &info, H5O_INFO_BASIC) >= 0 && info.type == H5O_TYPE_GROUP;
}

bool Hdf5File::IsNumericDataset(const std::string& object) const {
  if (!Exists(object) || IsGroup(object)) return false;
  const Handle dset = impl_->OpenDataset(object);
  const Handle type(H5Dget_type(dset.get()), H5Tclose);
  const H5T_class_t type_class = H5Tget_class(type.get());
  return type_class == H5T_FLOAT || type_class == H5T_INTEGER;
}

void WriteHdf5Atomically(const std::filesystem::path& path,
                         const std::function<void(Hdf5File&)>& write) {
  // Same folder, so the rename is atomic on the same file system.
  std::filesystem::path temporary = path;
  temporary += fmt::format(".tmp-{}", ::getpid());
  try {
    {
      Hdf5File file = Hdf5File::Create(temporary);
      write(file);
    }  // closed and flushed here
    std::filesystem::rename(temporary, path);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
}

std::string JoinPath(std::initializer_list<std::string_view> parts) {
  std::string out;
  for (std::string_view part : parts) {
    if (part.empty()) continue;
    if (part.front() != '/') out += '/';
    out += part;
  }
  return out.empty() ? "/" : out;
}

}  // namespace impactlab
