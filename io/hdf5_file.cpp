#include "io/hdf5_file.h"

#include <algorithm>
#include <type_traits>
#include <unordered_set>

#include <fmt/format.h>
#include <hdf5.h>

#include "io/atomic_file.h"
#include "io/errors.h"

namespace impactlab {

// Not in the anonymous namespace: Hdf5File::Impl, a class with linkage, holds a
// Handle, which GCC warns of where this file is included in another (a unity
// build, -Wsubobject-linkage).
namespace hdf5_file_internal {

// Owns one HDF5 identifier. Close() reports the status; the destructor closes
// quietly, for error paths only (an exception is already on its way).
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
  herr_t Close() {
    const herr_t status = id_ >= 0 && close_ != nullptr ? close_(id_) : 0;
    id_ = -1;
    return status;
  }

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

}  // namespace hdf5_file_internal

namespace {

using hdf5_file_internal::Handle;

// HDF5 prints its error stack to stderr by default; we report our own errors.
// (Nothing to do if even that fails: the messages are only noise.)
void SilenceHdf5ErrorStack() { static_cast<void>(H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr)); }

// Grows the in-memory file by this much at a time.
constexpr std::size_t kCoreIncrementBytes = std::size_t{1} << 20;

}  // namespace

struct Hdf5File::Impl {
  std::filesystem::path path;
  Handle file;
  // The groups this process made or found in the file, so that writing a
  // dataset does not look its parents up again: a results file holds a
  // thousand small datasets, and walking every parent path with H5Lexists
  // was an eighth of writing one.
  std::unordered_set<std::string> known_groups;
  // The `units` attribute's type and dataspace, made once rather than for
  // each of the thousand datasets that carry one.
  Handle string_type, scalar_space;
  // The group the last dataset went into, kept open: datasets are written
  // group by group, and naming each by its full path made HDF5 walk the
  // path from the root again for every one.
  std::string open_group_name;
  Handle open_group;

  // `object`'s parent group, opened (or kept from the last call), and its name in it.
  std::pair<hid_t, std::string> ParentOf(const std::string& object) {
    const std::size_t found = object.rfind('/');
    const std::size_t slash = found == std::string::npos ? 0 : found;
    const std::string parent = slash == 0 ? "/" : object.substr(0, slash);
    if (!open_group.valid() || parent != open_group_name) {
      CheckedClose(open_group, parent);
      open_group = Make(H5Gopen2(file.get(), parent.c_str(), H5P_DEFAULT), H5Gclose, parent,
                        "open the group");
      open_group_name = parent;
    }
    return {open_group.get(), object.substr(found == std::string::npos ? 0 : slash + 1)};
  }

  [[noreturn]] void Fail(const std::string& object, const std::string& problem) const {
    throw InputError({path, object, std::nullopt}, problem);
  }

  void Check(herr_t status, const std::string& object, const char* what) const {
    if (status < 0) Fail(object, fmt::format("HDF5 could not {}", what));
  }

  // An identifier from HDF5, checked: negative means failure.
  Handle Make(hid_t id, herr_t (*close)(hid_t), const std::string& object, const char* what) const {
    if (id < 0) Fail(object, fmt::format("HDF5 could not {}", what));
    return Handle(id, close);
  }

  void CheckedClose(Handle& handle, const std::string& object) const {
    Check(handle.Close(), object, "close an object");
  }

  // H5Lexists and H5Aexists answer positive, zero or negative (an error).
  bool Answer(htri_t answer, const std::string& object, const char* what) const {
    if (answer < 0) Fail(object, fmt::format("HDF5 could not {}", what));
    return answer > 0;
  }

  bool LinkExists(const std::string& name) const {
    return Answer(H5Lexists(file.get(), name.c_str(), H5P_DEFAULT), name, "look up a link");
  }

  Handle VariableStringType(const std::string& object) const {
    Handle type = Make(H5Tcopy(H5T_C_S1), H5Tclose, object, "copy the string type");
    Check(H5Tset_size(type.get(), H5T_VARIABLE), object, "set the string type's size");
    Check(H5Tset_cset(type.get(), H5T_CSET_UTF8), object, "set the string type's character set");
    return type;
  }

  // Groups remember creation order, so runs list in manifest order.
  Handle OrderedGroupCreation(const std::string& object) const {
    Handle plist = Make(H5Pcreate(H5P_GROUP_CREATE), H5Pclose, object, "create a property list");
    Check(H5Pset_link_creation_order(plist.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED),
          object, "track creation order");
    return plist;
  }

  // The transfer of `count` variable-length strings. HDF5 1.10 converts them
  // (pointers in memory, heap references on file) through a buffer it
  // allocates and zeroes on every write, 1 MB unless told: 1 MB cleared and
  // faulted in for every list of names was most of the typed-in thesis's
  // writing. Sized to the strings' references instead (ample: 16 bytes each).
  Handle StringTransfer(std::size_t count, const std::string& object) const {
    Handle plist = Make(H5Pcreate(H5P_DATASET_XFER), H5Pclose, object, "create a property list");
    Check(H5Pset_buffer(plist.get(), 64 * std::max<std::size_t>(count, 1), nullptr, nullptr),
          object, "size the conversion buffer");
    return plist;
  }

  Handle Dataspace(const std::vector<hsize_t>& dims, const std::string& object) const {
    return Make(dims.empty()
                    ? H5Screate(H5S_SCALAR)
                    : H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
                H5Sclose, object, "create a dataspace");
  }

  // Makes every missing group on the way to `object` (with creation order).
  void EnsureParentGroups(const std::string& object) {
    std::size_t pos = 1;
    while ((pos = object.find('/', pos)) != std::string::npos) {
      std::string group = object.substr(0, pos);
      ++pos;
      if (known_groups.contains(group)) continue;
      if (!LinkExists(group)) {
        Handle plist = OrderedGroupCreation(group);
        Handle g =
            Make(H5Gcreate2(file.get(), group.c_str(), H5P_DEFAULT, plist.get(), H5P_DEFAULT),
                 H5Gclose, group, "create the group");
        CheckedClose(g, group);
        CheckedClose(plist, group);
      }
      known_groups.insert(std::move(group));
    }
  }

  Handle CreateDataset(const std::string& name, hid_t type, const std::vector<hsize_t>& dims) {
    EnsureParentGroups(name);
    Handle space = Dataspace(dims, name);
    const auto [parent, leaf] = ParentOf(name);
    Handle dset = Make(
        H5Dcreate2(parent, leaf.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
        H5Dclose, name, "create the dataset (does it exist already?)");
    CheckedClose(space, name);
    return dset;
  }

  // Whether every link on the way to `name` exists (H5Lexists needs its parents).
  bool PathExists(const std::string& name) const {
    if (name == "/") return true;
    std::size_t pos = 1;
    while (true) {
      pos = name.find('/', pos);
      if (!LinkExists(name.substr(0, pos))) return false;
      if (pos == std::string::npos) return true;
      ++pos;
    }
  }

  // Opened in one walk down the path; only a failure looks again, to say why.
  Handle OpenObject(const std::string& name) const {
    Handle object(H5Oopen(file.get(), name.c_str(), H5P_DEFAULT), H5Oclose);
    if (object.valid()) return object;
    if (!PathExists(name)) Fail(name, "not found in the results file");
    Fail(name, "HDF5 could not open the object");
  }

  Handle OpenDataset(const std::string& name) const {
    Handle dset(H5Dopen2(file.get(), name.c_str(), H5P_DEFAULT), H5Dclose);
    if (dset.valid()) return dset;
    if (!PathExists(name)) Fail(name, "not found in the results file");
    Fail(name, "is not a dataset");
  }

  hssize_t ElementCount(const Handle& dset, const std::string& name) const {
    const Handle space = Make(H5Dget_space(dset.get()), H5Sclose, name, "get the dataspace");
    const hssize_t n = H5Sget_simple_extent_npoints(space.get());
    if (n < 0) Fail(name, "HDF5 could not count the elements");
    return n;
  }

  void DeleteAttributeIfPresent(hid_t obj, const std::string& object, const std::string& name) {
    if (Answer(H5Aexists(obj, name.c_str()), object, "look up an attribute")) {
      Check(H5Adelete(obj, name.c_str()), object, "delete an attribute");
    }
  }

  // `fresh`: the object was just created, so it has no attribute to replace.
  void WriteStringAttribute(hid_t obj, const std::string& object, const std::string& name,
                            const std::string& value, bool fresh = false) {
    if (!string_type.valid()) string_type = VariableStringType(object);
    if (!scalar_space.valid()) scalar_space = Dataspace({}, object);
    if (!fresh) DeleteAttributeIfPresent(obj, object, name);
    Handle attr = Make(H5Acreate2(obj, name.c_str(), string_type.get(), scalar_space.get(),
                                  H5P_DEFAULT, H5P_DEFAULT),
                       H5Aclose, object, "create an attribute");
    const char* text = value.c_str();
    Check(H5Awrite(attr.get(), string_type.get(), &text), object, "write an attribute");
    CheckedClose(attr, object);
  }

  void WriteIntegerAttribute(hid_t obj, const std::string& object, const std::string& name,
                             const std::vector<long long>& values, bool scalar) {
    Handle space =
        Dataspace(scalar ? std::vector<hsize_t>{} : std::vector<hsize_t>{values.size()}, object);
    DeleteAttributeIfPresent(obj, object, name);
    Handle attr =
        Make(H5Acreate2(obj, name.c_str(), H5T_NATIVE_LLONG, space.get(), H5P_DEFAULT, H5P_DEFAULT),
             H5Aclose, object, "create an attribute");
    Check(H5Awrite(attr.get(), H5T_NATIVE_LLONG, values.data()), object, "write an attribute");
    CheckedClose(attr, object);
    CheckedClose(space, object);
  }

  Handle OpenAttribute(const std::string& object, const std::string& name) const {
    const Handle obj = OpenObject(object);
    if (!Answer(H5Aexists(obj.get(), name.c_str()), object, "look up an attribute")) {
      Fail(object, fmt::format("has no attribute '{}'", name));
    }
    return Make(H5Aopen(obj.get(), name.c_str(), H5P_DEFAULT), H5Aclose, object,
                "open an attribute");
  }

  // The finished in-memory file as bytes, then the file closed: every status
  // checked, and no disk I/O by HDF5 (core driver without backing store).
  std::string CloseToImage() {
    CheckedClose(string_type, "");
    CheckedClose(scalar_space, "");
    CheckedClose(open_group, open_group_name);
    Check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), "", "flush the file");
    const ssize_t size = H5Fget_file_image(file.get(), nullptr, 0);
    if (size <= 0) Fail("", "HDF5 could not size the file image");
    std::string image(static_cast<std::size_t>(size), '\0');
    if (H5Fget_file_image(file.get(), image.data(), image.size()) != size) {
      Fail("", "HDF5 could not copy the file image");
    }
    const ssize_t open_objects = H5Fget_obj_count(file.get(), H5F_OBJ_ALL);
    if (open_objects != 1) {
      Fail("", fmt::format("{} HDF5 objects still open at close (a bug)", open_objects - 1));
    }
    Check(file.Close(), "", "close the file");
    return image;
  }
};

Hdf5File::Hdf5File(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

// The version compiled against, which is the one linked: HDF5 is linked
// statically. Asking the library (H5get_libversion) would initialise all of
// it, a millisecond of `impactlab --version`.
std::string Hdf5Version() {
  return fmt::format("{}.{}.{}", H5_VERS_MAJOR, H5_VERS_MINOR, H5_VERS_RELEASE);
}

std::int64_t Hdf5File::NativeId() const {
  static_assert(std::is_same_v<hid_t, std::int64_t>, "a hid_t is kept as int64_t");
  return impl_->file.get();
}
Hdf5File::Hdf5File(Hdf5File&&) noexcept = default;
Hdf5File& Hdf5File::operator=(Hdf5File&&) noexcept = default;
Hdf5File::~Hdf5File() = default;

Hdf5File Hdf5File::CreateInMemory(const std::filesystem::path& path) {
  SilenceHdf5ErrorStack();
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  // The root group remembers creation order too.
  Handle create = impl->Make(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "", "create a property list");
  impl->Check(
      H5Pset_link_creation_order(create.get(), H5P_CRT_ORDER_TRACKED | H5P_CRT_ORDER_INDEXED), "",
      "track creation order");
  Handle access = impl->Make(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "", "create a property list");
  impl->Check(H5Pset_fapl_core(access.get(), kCoreIncrementBytes, /*backing_store=*/0), "",
              "select the in-memory driver");
  {
    // A results file holds a few thousand small objects; HDF5's default
    // metadata cache (2 MB at first, up to 32 MB) is sized for far larger
    // files, and filling its pages was most of a small session's page
    // faults (the typed-in thesis: CPU 0.157 -> 0.126 s a reduce).
    H5AC_cache_config_t config;
    config.version = H5AC__CURR_CACHE_CONFIG_VERSION;
    impl->Check(H5Pget_mdc_config(access.get(), &config), "", "read the metadata cache's settings");
    config.set_initial_size = true;
    config.initial_size = 64 * 1024;
    config.min_size = 64 * 1024;
    config.max_size = 256 * 1024;
    impl->Check(H5Pset_mdc_config(access.get(), &config), "", "size the metadata cache");
  }
  // The name only identifies the in-memory file; nothing is written there.
  // Nor read: HDF5 first opens the name without creating, to find a file it
  // already has open, and its core driver then read all of an existing file
  // there into memory (an earlier results file: the typed-in thesis's 870 kB,
  // 211 page faults, ~2 ms; the photo sample's 5.4 MB). A name ending in '/'
  // can be no regular file, so that open always fails.
  const std::string never_a_file = path.string() + "/";
  impl->file =
      impl->Make(H5Fcreate(never_a_file.c_str(), H5F_ACC_TRUNC, create.get(), access.get()),
                 H5Fclose, "", "create the results file in memory");
  impl->CheckedClose(access, "");
  impl->CheckedClose(create, "");
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
  Handle dset = impl_->CreateDataset(name, H5T_IEEE_F64LE, {});
  impl_->Check(H5Dwrite(dset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, &value), name,
               "write the dataset");
  impl_->WriteStringAttribute(dset.get(), name, "units", std::string(units), /*fresh=*/true);
  impl_->CheckedClose(dset, name);
}

void Hdf5File::WriteVector(const std::string& name, const std::vector<double>& values,
                           std::string_view units) {
  Handle dset = impl_->CreateDataset(name, H5T_IEEE_F64LE, {values.size()});
  if (!values.empty()) {
    impl_->Check(
        H5Dwrite(dset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name,
        "write the dataset");
  }
  impl_->WriteStringAttribute(dset.get(), name, "units", std::string(units), /*fresh=*/true);
  impl_->CheckedClose(dset, name);
}

void Hdf5File::WriteIntegers(const std::string& name, const std::vector<long long>& values) {
  Handle dset = impl_->CreateDataset(name, H5T_STD_I64LE, {values.size()});
  if (!values.empty()) {
    impl_->Check(
        H5Dwrite(dset.get(), H5T_NATIVE_LLONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name,
        "write the dataset");
  }
  impl_->CheckedClose(dset, name);
}

void Hdf5File::WriteStrings(const std::string& name, const std::vector<std::string>& values) {
  Handle type = impl_->VariableStringType(name);
  Handle dset = impl_->CreateDataset(name, type.get(), {values.size()});
  std::vector<const char*> text;
  for (const std::string& v : values) text.push_back(v.c_str());
  if (!text.empty()) {
    Handle transfer = impl_->StringTransfer(text.size(), name);
    impl_->Check(H5Dwrite(dset.get(), type.get(), H5S_ALL, H5S_ALL, transfer.get(), text.data()),
                 name, "write the dataset");
    impl_->CheckedClose(transfer, name);
  }
  impl_->CheckedClose(dset, name);
  impl_->CheckedClose(type, name);
}

void Hdf5File::WriteBytes(const std::string& name, const std::vector<unsigned char>& bytes) {
  Handle dset = impl_->CreateDataset(name, H5T_STD_U8LE, {bytes.size()});
  if (!bytes.empty()) {
    impl_->Check(
        H5Dwrite(dset.get(), H5T_NATIVE_UCHAR, H5S_ALL, H5S_ALL, H5P_DEFAULT, bytes.data()), name,
        "write the dataset");
  }
  impl_->CheckedClose(dset, name);
}

std::vector<unsigned char> Hdf5File::ReadBytes(const std::string& name) const {
  const Handle dset = impl_->OpenDataset(name);
  std::vector<unsigned char> bytes(static_cast<std::size_t>(impl_->ElementCount(dset, name)));
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
  Handle obj = impl_->OpenObject(object);
  impl_->WriteStringAttribute(obj.get(), object, name, value);
  impl_->CheckedClose(obj, object);
}

void Hdf5File::SetAttribute(const std::string& object, const std::string& name, long long value) {
  Handle obj = impl_->OpenObject(object);
  impl_->WriteIntegerAttribute(obj.get(), object, name, {value}, /*scalar=*/true);
  impl_->CheckedClose(obj, object);
}

void Hdf5File::SetAttribute(const std::string& object, const std::string& name,
                            const std::vector<long long>& values) {
  Handle obj = impl_->OpenObject(object);
  impl_->WriteIntegerAttribute(obj.get(), object, name, values, /*scalar=*/false);
  impl_->CheckedClose(obj, object);
}

bool Hdf5File::Exists(const std::string& object) const { return impl_->PathExists(object); }

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
    impl_->Check(H5Literate(obj.get(), H5_INDEX_NAME, H5_ITER_INC, &index, collect, &names), group,
                 "list the group");
  }
  return names;
}

double Hdf5File::ReadScalar(const std::string& name) const {
  const Handle dset = impl_->OpenDataset(name);
  if (impl_->ElementCount(dset, name) != 1) impl_->Fail(name, "expected a scalar dataset");
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
  std::vector<double> values(static_cast<std::size_t>(impl_->ElementCount(dset, name)));
  if (!values.empty()) {
    impl_->Check(
        H5Dread(dset.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name,
        "read the dataset");
  }
  return values;
}

std::vector<long long> Hdf5File::ReadIntegers(const std::string& name) const {
  const Handle dset = impl_->OpenDataset(name);
  std::vector<long long> values(static_cast<std::size_t>(impl_->ElementCount(dset, name)));
  if (!values.empty()) {
    impl_->Check(
        H5Dread(dset.get(), H5T_NATIVE_LLONG, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), name,
        "read the dataset");
  }
  return values;
}

std::vector<std::string> Hdf5File::ReadStrings(const std::string& name) const {
  const Handle dset = impl_->OpenDataset(name);
  const Handle type = impl_->VariableStringType(name);
  std::vector<char*> text(static_cast<std::size_t>(impl_->ElementCount(dset, name)), nullptr);
  std::vector<std::string> values;
  if (text.empty()) return values;
  impl_->Check(H5Dread(dset.get(), type.get(), H5S_ALL, H5S_ALL, H5P_DEFAULT, text.data()), name,
               "read the dataset");
  for (char* t : text) values.emplace_back(t != nullptr ? t : "");
  const Handle space = impl_->Make(H5Dget_space(dset.get()), H5Sclose, name, "get the dataspace");
  impl_->Check(H5Dvlen_reclaim(type.get(), space.get(), H5P_DEFAULT, text.data()), name,
               "free the strings read");
  return values;
}

std::string Hdf5File::ReadStringAttribute(const std::string& object,
                                          const std::string& name) const {
  const Handle attr = impl_->OpenAttribute(object, name);
  const Handle type = impl_->VariableStringType(object);
  char* text = nullptr;
  impl_->Check(H5Aread(attr.get(), type.get(), &text), object, "read an attribute");
  std::string value = text != nullptr ? text : "";
  impl_->Check(H5free_memory(text), object, "free the attribute read");
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
  const Handle space =
      impl_->Make(H5Aget_space(attr.get()), H5Sclose, object, "get an attribute's dataspace");
  const hssize_t count = H5Sget_simple_extent_npoints(space.get());
  if (count < 0) impl_->Fail(object, "HDF5 could not count an attribute's elements");
  std::vector<long long> values(static_cast<std::size_t>(count));
  impl_->Check(H5Aread(attr.get(), H5T_NATIVE_LLONG, values.data()), object, "read an attribute");
  return values;
}

bool Hdf5File::HasAttribute(const std::string& object, const std::string& name) const {
  if (!Exists(object)) return false;
  const Handle obj = impl_->OpenObject(object);
  return impl_->Answer(H5Aexists(obj.get(), name.c_str()), object, "look up an attribute");
}

std::vector<std::string> Hdf5File::AttributeNames(const std::string& object) const {
  const Handle obj = impl_->OpenObject(object);
  std::vector<std::string> names;
  const auto add = [](hid_t, const char* name, const H5A_info_t*, void* out) -> herr_t {
    static_cast<std::vector<std::string>*>(out)->emplace_back(name);
    return 0;
  };
  impl_->Check(H5Aiterate2(obj.get(), H5_INDEX_NAME, H5_ITER_INC, nullptr, add, &names), object,
               "list the attributes");
  return names;
}

bool Hdf5File::IsGroup(const std::string& object) const {
  if (!Exists(object)) return false;
  H5O_info_t info;
  const Handle obj = impl_->OpenObject(object);
  impl_->Check(H5Oget_info2(obj.get(), &info, H5O_INFO_BASIC), object, "get an object's type");
  return info.type == H5O_TYPE_GROUP;
}

bool Hdf5File::IsNumericDataset(const std::string& object) const {
  if (!Exists(object) || IsGroup(object)) return false;
  const Handle dset = impl_->OpenDataset(object);
  const Handle type =
      impl_->Make(H5Dget_type(dset.get()), H5Tclose, object, "get a dataset's type");
  const H5T_class_t type_class = H5Tget_class(type.get());
  if (type_class == H5T_NO_CLASS) impl_->Fail(object, "HDF5 could not get a type's class");
  return type_class == H5T_FLOAT || type_class == H5T_INTEGER;
}

void WriteHdf5Atomically(const std::filesystem::path& path,
                         const std::function<void(Hdf5File&)>& write) {
  std::string image;
  {
    Hdf5File file = Hdf5File::CreateInMemory(path);
    write(file);
    image = file.impl_->CloseToImage();
  }
  WriteFileAtomically(path, image);
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
