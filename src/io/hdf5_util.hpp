#pragma once
// Thin RAII and attribute helpers over the HDF5 C API. HDF5's own error printing is switched off;
// failures become UserError with a message naming the file and object.
#include <hdf5.h>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace sphdisk::h5 {

class Handle {
 public:
  Handle() = default;
  Handle(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  Handle(Handle&& o) noexcept : id_(o.id_), close_(o.close_) { o.id_ = -1; }
  Handle& operator=(Handle&& o) noexcept {
    reset();
    id_ = o.id_;
    close_ = o.close_;
    o.id_ = -1;
    return *this;
  }
  ~Handle() { reset(); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  hid_t get() const { return id_; }
  operator hid_t() const { return id_; }
  bool valid() const { return id_ >= 0; }
  void reset() {
    if (id_ >= 0 && close_) close_(id_);
    id_ = -1;
  }

 private:
  hid_t id_ = -1;
  herr_t (*close_)(hid_t) = nullptr;
};

void silence_errors();  // turn off HDF5's automatic error stack printing (once per process)

// Runs read_all() in a forked child first. The HDF5 library (1.10) can crash on corrupt metadata
// (fuzzing found heap errors inside it: tests/fuzz_regressions/); a crash in the child becomes a
// UserError here instead of taking the run down. The child's UserErrors are left for the real read
// in this process to report.
void isolate_library_crashes(const std::string& path, const std::function<void()>& read_all);

// read() tried first in a child (isolate_library_crashes), then here: its result.
template <class Read>
auto read_isolated(const std::string& path, Read&& read) {
  isolate_library_crashes(path, [&] { read(); });
  return read();
}

// access: a file-access property list (shared_file_access: one file written by all ranks).
Handle create_file(const std::string& path, hid_t access = H5P_DEFAULT);
Handle open_file_readonly(const std::string& path);  // throws UserError naming the path
Handle create_group(hid_t parent, const std::string& name);
Handle open_group(hid_t parent, const std::string& name, const std::string& file);  // throws if missing
bool exists(hid_t parent, const std::string& name);
bool exists_attr(hid_t obj, const std::string& name);

void write_attr(hid_t obj, const std::string& name, double v);
void write_attr(hid_t obj, const std::string& name, long long v);
void write_attr(hid_t obj, const std::string& name, const std::string& v);
void write_attr(hid_t obj, const std::string& name, const std::vector<double>& v);
void write_attr(hid_t obj, const std::string& name, const std::vector<std::uint32_t>& v);
void write_attr(hid_t obj, const std::string& name, const std::vector<std::uint64_t>& v);

bool has_attr(hid_t obj, const std::string& name);
double read_attr_double(hid_t obj, const std::string& name, const std::string& file);  // throws if missing
std::vector<double> read_attr_doubles(hid_t obj, const std::string& name, const std::string& file);
std::string read_attr_string(hid_t obj, const std::string& name, const std::string& file);  // fixed- or variable-length

// Datasets of doubles/uint64 with shape rows x cols (cols == 1: a 1-D dataset), created whole and
// written in blocks of consecutive rows. With a collective transfer list (shared_transfer) every
// rank writes its own block, and every rank must call write_rows (rows = 0 if it has none).
Handle create_dataset(hid_t group, const std::string& name, bool u64, std::size_t rows, std::size_t cols);
void write_rows(hid_t dataset, const double* data, std::size_t first_row, std::size_t rows, std::size_t cols,
                hid_t transfer = H5P_DEFAULT);
void write_rows(hid_t dataset, const std::uint64_t* data, std::size_t first_row, std::size_t rows,
                hid_t transfer = H5P_DEFAULT);
void write_dataset(hid_t group, const std::string& name, const double* data, std::size_t rows, std::size_t cols);
void write_dataset(hid_t group, const std::string& name, const std::uint64_t* data, std::size_t rows);
// Share `part` of `parts` of a dataset's n rows: rows [n part / parts, n (part + 1) / parts), so
// that each of P ranks reads 1/P of a file (the default share is the whole dataset).
struct RowShare {
  std::size_t part = 0, parts = 1;
  std::size_t first(std::size_t n) const { return n / parts * part + n % parts * part / parts; }
  std::size_t count(std::size_t n) const { return RowShare{part + 1, parts}.first(n) - first(n); }
};

// Reads the share's rows of a dataset as doubles (or uint64); rows and cols return the dataset's
// whole shape (rows of all shares).
std::vector<double> read_dataset_doubles(hid_t group, const std::string& name, const std::string& file,
                                         std::size_t& rows, std::size_t& cols, RowShare share = {});
std::vector<std::uint64_t> read_dataset_u64(hid_t group, const std::string& name, const std::string& file,
                                            std::size_t& rows, RowShare share = {});

}  // namespace sphdisk::h5
