#pragma once
// A small RAII layer over the HDF5 C API: just what trial and checkpoint files need.
// Debian's HDF5 is not built thread-safe, so every call made through this layer holds one
// process-wide lock (hdf5_lock); files written the same way are byte-identical (no timestamps).
#include <hdf5.h>

#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include "bvc3d/core/params.hpp"

namespace bvc3d::h5 {

std::unique_lock<std::recursive_mutex> hdf5_lock();

class Handle {
public:
    Handle() = default;
    Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
    Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
    Handle& operator=(Handle&& o) noexcept;
    Handle(const Handle&) = delete;
    Handle& operator=(const Handle&) = delete;
    ~Handle() { reset(); }
    void reset();  // close now
    hid_t id() const { return id_; }
    operator hid_t() const { return id_; }

private:
    hid_t id_ = -1;
    herr_t (*close_)(hid_t) = nullptr;
};

// A new file built in memory (HDF5's core driver): nothing touches the disk until the caller
// writes file_image() itself, so a full disk is reported with its reason (AtomicFile) and never
// leaves HDF5 holding a half-written file. `name` must be unique among open files.
Handle create_memory_file(const std::string& name);
std::string file_image(hid_t file);         // the bytes of the file as it stands (flushed first)
Handle open_file(const std::string& path);  // read-only
Handle create_group(hid_t loc, const std::string& name);
Handle open_group(hid_t loc, const std::string& name);
bool exists(hid_t loc, const std::string& name);
bool exists_attr(hid_t obj, const std::string& name);

void write_attr(hid_t obj, const std::string& name, const std::string& value);
void write_attr(hid_t obj, const std::string& name, double value);
void write_attr(hid_t obj, const std::string& name, std::int64_t value);
void write_attr_u64(hid_t obj, const std::string& name, std::uint64_t value);  // stored as uint64
std::string read_attr_string(hid_t obj, const std::string& name);
double read_attr_double(hid_t obj, const std::string& name);
std::int64_t read_attr_int(hid_t obj, const std::string& name);
// An integer attribute of any integer type as uint64 (InputError if negative or not an integer).
std::uint64_t read_attr_u64(hid_t obj, const std::string& name);
// The type class (H5T_INTEGER, H5T_FLOAT, H5T_STRING, ...) of an attribute or a dataset.
H5T_class_t attr_class(hid_t obj, const std::string& name);
H5T_class_t dataset_class(hid_t loc, const std::string& name);
// A parameter value as an attribute: reals as float64, integers as int64, text, flags as int64 0/1,
// lists as float64 datasets are not attributes (rejected).
void write_attr(hid_t obj, const std::string& name, const params::Value& value);
// Any scalar attribute as a value (float → double, integer → long long, text → string).
params::Value read_attr(hid_t obj, const std::string& name);
std::vector<std::string> attribute_names(hid_t obj);

// Row-major datasets of 1 or 2 dimensions; chunked and compressed when `compress` (for h5py users
// this is transparent).
void write(hid_t loc, const std::string& name, const std::vector<double>& v, std::vector<std::size_t> dims,
           bool compress = true);
void write(hid_t loc, const std::string& name, const std::vector<float>& v, std::vector<std::size_t> dims,
           bool compress = true);
void write(hid_t loc, const std::string& name, const std::vector<std::int64_t>& v, std::vector<std::size_t> dims,
           bool compress = true);
void write(hid_t loc, const std::string& name, const std::vector<std::uint8_t>& v, std::vector<std::size_t> dims,
           bool compress = true);

std::vector<std::size_t> dims(hid_t loc, const std::string& name);
// What a dataset's elements are, for readers that take any stored type.
enum class Element { f64, f32, integer, other };
Element element(hid_t loc, const std::string& name);
std::vector<double> read_doubles(hid_t loc, const std::string& name);
std::vector<float> read_floats(hid_t loc, const std::string& name);
std::vector<std::int64_t> read_ints(hid_t loc, const std::string& name);
std::vector<std::uint8_t> read_bytes(hid_t loc, const std::string& name);

}  // namespace bvc3d::h5
