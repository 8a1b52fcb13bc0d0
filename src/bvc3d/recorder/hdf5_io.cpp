#include "bvc3d/recorder/hdf5_io.hpp"

#include <algorithm>
#include <stdexcept>

#include "bvc3d/core/error.hpp"
#include "bvc3d/core/memory.hpp"

namespace bvc3d::h5 {

namespace {

[[noreturn]] void fail(const std::string& what) { throw InputError("HDF5: " + what); }

hid_t check(hid_t id, const std::string& what) {
    if (id < 0) fail(what);
    return id;
}

void check(herr_t e, const std::string& what) {
    if (e < 0) fail(what);
}

// Quiet HDF5's own error printing (per thread in thread-safe builds); our exceptions say what failed.
void silence() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

template <class T>
void write_any(hid_t loc, const std::string& name, const std::vector<T>& v, std::vector<std::size_t> shape,
               hid_t mem_type, bool compress) {
    auto lock = hdf5_lock();
    std::size_t n = 1;
    for (auto d : shape) n *= d;
    if (n != v.size()) throw std::logic_error("HDF5 write: shape does not match data for " + name);
    std::vector<hsize_t> hd(shape.begin(), shape.end());
    Handle space(check(H5Screate_simple(static_cast<int>(hd.size()), hd.data(), nullptr), "dataspace " + name),
                 H5Sclose);
    Handle dcpl(check(H5Pcreate(H5P_DATASET_CREATE), "plist"), H5Pclose);
    check(H5Pset_obj_track_times(dcpl, false), "track times");
    if (compress && n > 0) {
        std::vector<hsize_t> chunk = hd;
        // About 1 MB chunks of whole rows.
        const hsize_t row = hd.size() > 1 ? std::max<hsize_t>(hd[1], 1) : 1;
        chunk[0] = std::max<hsize_t>(1, std::min<hsize_t>(hd[0], (1u << 20) / (sizeof(T) * row)));
        check(H5Pset_chunk(dcpl, static_cast<int>(chunk.size()), chunk.data()), "chunk " + name);
        check(H5Pset_shuffle(dcpl), "shuffle");
        check(H5Pset_deflate(dcpl, 1), "deflate");
    }
    Handle ds(check(H5Dcreate2(loc, name.c_str(), mem_type, space, H5P_DEFAULT, dcpl, H5P_DEFAULT), "create " + name),
              H5Dclose);
    if (n > 0) check(H5Dwrite(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), "write " + name);
}

template <class T>
std::vector<T> read_any(hid_t loc, const std::string& name, hid_t mem_type) {
    auto lock = hdf5_lock();
    Handle ds(check(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), "no dataset '" + name + "'"), H5Dclose);
    Handle space(check(H5Dget_space(ds), "space " + name), H5Sclose);
    const hssize_t n = H5Sget_simple_extent_npoints(space);
    // A damaged or hostile file may claim any size: refuse what cannot fit before allocating it.
    if (const double bytes = static_cast<double>(std::max<hssize_t>(n, 0)) * sizeof(T); bytes > 1e8)
        check_memory(bytes, "dataset '" + name + "'", "the file is probably damaged");
    std::vector<T> out(static_cast<std::size_t>(std::max<hssize_t>(n, 0)));
    if (n > 0) check(H5Dread(ds, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.data()), "read " + name);
    return out;
}

Handle attr_for_write(hid_t obj, const std::string& name, hid_t type, hid_t space) {
    if (H5Aexists(obj, name.c_str()) > 0) check(H5Adelete(obj, name.c_str()), "delete attribute " + name);
    return Handle(check(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), "attribute " + name),
                  H5Aclose);
}

}  // namespace

std::unique_lock<std::recursive_mutex> hdf5_lock() {
    static std::recursive_mutex m;
    silence();
    return std::unique_lock<std::recursive_mutex>(m);
}

Handle& Handle::operator=(Handle&& o) noexcept {
    if (this != &o) {
        reset();
        id_ = o.id_;
        close_ = o.close_;
        o.id_ = -1;
    }
    return *this;
}

void Handle::reset() {
    if (id_ >= 0 && close_) {
        auto lock = hdf5_lock();
        close_(id_);
    }
    id_ = -1;
}

Handle create_memory_file(const std::string& name) {
    auto lock = hdf5_lock();
    Handle fcpl(check(H5Pcreate(H5P_FILE_CREATE), "plist"), H5Pclose);
    check(H5Pset_obj_track_times(fcpl, false), "track times");
    Handle fapl(check(H5Pcreate(H5P_FILE_ACCESS), "plist"), H5Pclose);
    check(H5Pset_fapl_core(fapl, 1 << 20, false), "core driver");  // grows by 1 MiB, no backing file
    return Handle(check(H5Fcreate(name.c_str(), H5F_ACC_TRUNC, fcpl, fapl), "cannot create '" + name + "' in memory"),
                  H5Fclose);
}

std::string file_image(hid_t file) {
    auto lock = hdf5_lock();
    check(H5Fflush(file, H5F_SCOPE_GLOBAL), "flush");
    const ssize_t n = H5Fget_file_image(file, nullptr, 0);
    if (n < 0) fail("file image");
    std::string bytes(static_cast<std::size_t>(n), '\0');
    if (H5Fget_file_image(file, bytes.data(), bytes.size()) != n) fail("file image");
    return bytes;
}

Handle open_file(const std::string& path) {
    auto lock = hdf5_lock();
    return Handle(
        check(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), "cannot open '" + path + "' as an HDF5 file"),
        H5Fclose);
}

Handle create_group(hid_t loc, const std::string& name) {
    auto lock = hdf5_lock();
    Handle gcpl(check(H5Pcreate(H5P_GROUP_CREATE), "plist"), H5Pclose);
    check(H5Pset_obj_track_times(gcpl, false), "track times");
    return Handle(check(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, gcpl, H5P_DEFAULT), "group " + name), H5Gclose);
}

Handle open_group(hid_t loc, const std::string& name) {
    auto lock = hdf5_lock();
    return Handle(check(H5Gopen2(loc, name.c_str(), H5P_DEFAULT), "no group '" + name + "'"), H5Gclose);
}

bool exists(hid_t loc, const std::string& name) {
    auto lock = hdf5_lock();
    return H5Lexists(loc, name.c_str(), H5P_DEFAULT) > 0;
}

bool exists_attr(hid_t obj, const std::string& name) {
    auto lock = hdf5_lock();
    return H5Aexists(obj, name.c_str()) > 0;
}

void write_attr(hid_t obj, const std::string& name, const std::string& value) {
    auto lock = hdf5_lock();
    // Variable-length UTF-8: h5py reads it as a Python str.
    Handle type(check(H5Tcopy(H5T_C_S1), "type"), H5Tclose);
    check(H5Tset_size(type, H5T_VARIABLE), "type size");
    check(H5Tset_cset(type, H5T_CSET_UTF8), "cset");
    Handle space(check(H5Screate(H5S_SCALAR), "space"), H5Sclose);
    Handle a = attr_for_write(obj, name, type, space);
    const char* text = value.c_str();
    check(H5Awrite(a, type, &text), "write attribute " + name);
}

void write_attr(hid_t obj, const std::string& name, double value) {
    auto lock = hdf5_lock();
    Handle space(check(H5Screate(H5S_SCALAR), "space"), H5Sclose);
    Handle a = attr_for_write(obj, name, H5T_IEEE_F64LE, space);
    check(H5Awrite(a, H5T_NATIVE_DOUBLE, &value), "write attribute " + name);
}

void write_attr(hid_t obj, const std::string& name, std::int64_t value) {
    auto lock = hdf5_lock();
    Handle space(check(H5Screate(H5S_SCALAR), "space"), H5Sclose);
    Handle a = attr_for_write(obj, name, H5T_STD_I64LE, space);
    check(H5Awrite(a, H5T_NATIVE_INT64, &value), "write attribute " + name);
}

void write_attr_u64(hid_t obj, const std::string& name, std::uint64_t value) {
    auto lock = hdf5_lock();
    Handle space(check(H5Screate(H5S_SCALAR), "space"), H5Sclose);
    Handle a = attr_for_write(obj, name, H5T_STD_U64LE, space);
    check(H5Awrite(a, H5T_NATIVE_UINT64, &value), "write attribute " + name);
}

std::uint64_t read_attr_u64(hid_t obj, const std::string& name) {
    auto lock = hdf5_lock();
    Handle a(check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "no attribute '" + name + "'"), H5Aclose);
    Handle type(check(H5Aget_type(a), "type"), H5Tclose);
    if (H5Tget_class(type) != H5T_INTEGER) fail("attribute '" + name + "' is not an integer");
    if (H5Tget_sign(type) == H5T_SGN_NONE) {
        std::uint64_t v = 0;
        check(H5Aread(a, H5T_NATIVE_UINT64, &v), "read attribute " + name);
        return v;
    }
    std::int64_t v = 0;
    check(H5Aread(a, H5T_NATIVE_INT64, &v), "read attribute " + name);
    if (v < 0) fail("attribute '" + name + "' is negative (" + std::to_string(v) + ")");
    return static_cast<std::uint64_t>(v);
}

H5T_class_t attr_class(hid_t obj, const std::string& name) {
    auto lock = hdf5_lock();
    Handle a(check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "no attribute '" + name + "'"), H5Aclose);
    Handle type(check(H5Aget_type(a), "type"), H5Tclose);
    return H5Tget_class(type);
}

H5T_class_t dataset_class(hid_t loc, const std::string& name) {
    auto lock = hdf5_lock();
    Handle ds(check(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), "no dataset '" + name + "'"), H5Dclose);
    Handle type(check(H5Dget_type(ds), "type"), H5Tclose);
    return H5Tget_class(type);
}

std::string read_attr_string(hid_t obj, const std::string& name) {
    auto lock = hdf5_lock();
    Handle a(check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "no attribute '" + name + "'"), H5Aclose);
    Handle type(check(H5Aget_type(a), "type"), H5Tclose);
    if (H5Tget_class(type) != H5T_STRING) fail("attribute '" + name + "' is not text");
    if (H5Tis_variable_str(type) > 0) {
        char* s = nullptr;
        Handle mem(check(H5Tcopy(H5T_C_S1), "type"), H5Tclose);
        check(H5Tset_size(mem, H5T_VARIABLE), "size");
        check(H5Tset_cset(mem, H5Tget_cset(type)), "cset");
        check(H5Aread(a, mem, &s), "read attribute " + name);
        std::string out = s ? s : "";
        Handle space(check(H5Aget_space(a), "space"), H5Sclose);
        H5Dvlen_reclaim(mem, space, H5P_DEFAULT, &s);
        return out;
    }
    std::string out(H5Tget_size(type), '\0');
    check(H5Aread(a, type, out.data()), "read attribute " + name);
    const auto end = out.find('\0');
    if (end != std::string::npos) out.resize(end);
    return out;
}

double read_attr_double(hid_t obj, const std::string& name) {
    auto lock = hdf5_lock();
    Handle a(check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "no attribute '" + name + "'"), H5Aclose);
    double v = 0;
    check(H5Aread(a, H5T_NATIVE_DOUBLE, &v), "read attribute " + name);
    return v;
}

std::int64_t read_attr_int(hid_t obj, const std::string& name) {
    auto lock = hdf5_lock();
    Handle a(check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "no attribute '" + name + "'"), H5Aclose);
    std::int64_t v = 0;
    check(H5Aread(a, H5T_NATIVE_INT64, &v), "read attribute " + name);
    return v;
}

void write_attr(hid_t obj, const std::string& name, const params::Value& value) {
    if (const auto* d = std::get_if<double>(&value)) write_attr(obj, name, *d);
    else if (const auto* i = std::get_if<long long>(&value)) write_attr(obj, name, static_cast<std::int64_t>(*i));
    else if (const auto* b = std::get_if<bool>(&value)) write_attr(obj, name, static_cast<std::int64_t>(*b));
    else if (const auto* t = std::get_if<std::string>(&value)) write_attr(obj, name, *t);
    else throw std::logic_error("HDF5: attribute '" + name + "' cannot hold a list");
}

params::Value read_attr(hid_t obj, const std::string& name) {
    auto lock = hdf5_lock();
    Handle a(check(H5Aopen(obj, name.c_str(), H5P_DEFAULT), "no attribute '" + name + "'"), H5Aclose);
    Handle type(check(H5Aget_type(a), "type"), H5Tclose);
    switch (H5Tget_class(type)) {
        case H5T_STRING:
            return read_attr_string(obj, name);
        case H5T_INTEGER:
            return static_cast<long long>(read_attr_int(obj, name));
        case H5T_FLOAT:
            return read_attr_double(obj, name);
        default:
            fail("attribute '" + name + "' is neither a number nor text");
    }
}

namespace {
herr_t collect_name(hid_t, const char* name, const H5A_info_t*, void* out) {
    static_cast<std::vector<std::string>*>(out)->emplace_back(name);
    return 0;
}
}  // namespace

std::vector<std::string> attribute_names(hid_t obj) {
    auto lock = hdf5_lock();
    std::vector<std::string> names;
    hsize_t at = 0;
    check(H5Aiterate2(obj, H5_INDEX_NAME, H5_ITER_INC, &at, collect_name, &names), "attribute names");
    return names;
}

void write(hid_t loc, const std::string& name, const std::vector<double>& v, std::vector<std::size_t> d, bool c) {
    write_any(loc, name, v, std::move(d), H5T_NATIVE_DOUBLE, c);
}
void write(hid_t loc, const std::string& name, const std::vector<float>& v, std::vector<std::size_t> d, bool c) {
    write_any(loc, name, v, std::move(d), H5T_NATIVE_FLOAT, c);
}
void write(hid_t loc, const std::string& name, const std::vector<std::int64_t>& v, std::vector<std::size_t> d, bool c) {
    write_any(loc, name, v, std::move(d), H5T_NATIVE_INT64, c);
}
void write(hid_t loc, const std::string& name, const std::vector<std::uint8_t>& v, std::vector<std::size_t> d, bool c) {
    write_any(loc, name, v, std::move(d), H5T_NATIVE_UINT8, c);
}

std::vector<std::size_t> dims(hid_t loc, const std::string& name) {
    auto lock = hdf5_lock();
    Handle ds(check(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), "no dataset '" + name + "'"), H5Dclose);
    Handle space(check(H5Dget_space(ds), "space"), H5Sclose);
    const int nd = H5Sget_simple_extent_ndims(space);
    std::vector<hsize_t> d(std::max(nd, 0));
    H5Sget_simple_extent_dims(space, d.data(), nullptr);
    return std::vector<std::size_t>(d.begin(), d.end());
}

Element element(hid_t loc, const std::string& name) {
    auto lock = hdf5_lock();
    Handle ds(check(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), "no dataset '" + name + "'"), H5Dclose);
    Handle type(check(H5Dget_type(ds), "type " + name), H5Tclose);
    switch (H5Tget_class(type)) {
        case H5T_FLOAT:
            return H5Tget_size(type) <= 4 ? Element::f32 : Element::f64;
        case H5T_INTEGER:
            return Element::integer;
        default:
            return Element::other;
    }
}

std::vector<double> read_doubles(hid_t loc, const std::string& n) {
    return read_any<double>(loc, n, H5T_NATIVE_DOUBLE);
}
std::vector<float> read_floats(hid_t loc, const std::string& n) { return read_any<float>(loc, n, H5T_NATIVE_FLOAT); }
std::vector<std::int64_t> read_ints(hid_t loc, const std::string& n) {
    return read_any<std::int64_t>(loc, n, H5T_NATIVE_INT64);
}
std::vector<std::uint8_t> read_bytes(hid_t loc, const std::string& n) {
    return read_any<std::uint8_t>(loc, n, H5T_NATIVE_UINT8);
}

}  // namespace bvc3d::h5
