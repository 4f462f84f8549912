#include "io/hdf5_util.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>

#include "core/error.hpp"

namespace sphdisk::h5 {

namespace {
[[noreturn]] void fail(const std::string& what) { throw UserError(what); }

// Object creation properties without modification times, so that identical data give
// byte-identical files (checked by the thread- and rank-independence tests).
Handle untimed(hid_t cls) {
  Handle p(H5Pcreate(cls), H5Pclose);
  H5Pset_obj_track_times(p, false);
  return p;
}

void write_attr_raw(hid_t obj, const std::string& name, hid_t type, const void* data, hsize_t n, bool scalar) {
  silence_errors();
  if (H5Aexists(obj, name.c_str()) > 0) H5Adelete(obj, name.c_str());
  Handle space(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose);
  Handle attr(H5Acreate2(obj, name.c_str(), type, space, H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
  if (!attr.valid() || H5Awrite(attr, type, data) < 0) fail("HDF5: cannot write attribute '" + name + "'");
}
}  // namespace

void isolate_library_crashes(const std::string& path, const std::function<void()>& read_all) {
  std::fflush(nullptr);
  const pid_t pid = ::fork();
  if (pid < 0) return;  // no isolation available: read directly
  if (pid == 0) {
    int code = 0;
    try {
      read_all();
    } catch (const UserError&) {
      code = 3;
    } catch (...) {
      code = 4;
    }
    ::_exit(code);
  }
  int status = 0;
  if (::waitpid(pid, &status, 0) < 0) return;
  const bool clean = WIFEXITED(status) && (WEXITSTATUS(status) == 0 || WEXITSTATUS(status) == 3);
  if (!clean)
    fail("'" + path + "' is corrupt: reading it crashed the HDF5 library (" +
         (WIFSIGNALED(status) ? "signal " + std::to_string(WTERMSIG(status)) : "exit " + std::to_string(WEXITSTATUS(status))) +
         "); use another copy");
}

void silence_errors() {
  static const bool done = [] {
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
    return true;
  }();
  (void)done;
}

Handle create_file(const std::string& path, hid_t access) {
  silence_errors();
  Handle f(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access), H5Fclose);
  if (!f.valid()) fail("cannot create HDF5 file '" + path + "': check that the directory exists and is writable");
  return f;
}

Handle open_file_readonly(const std::string& path) {
  silence_errors();
  if (H5Fis_hdf5(path.c_str()) <= 0)
    fail("cannot open '" + path + "' as an HDF5 file: it is missing, unreadable, truncated or not HDF5");
  Handle f(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!f.valid()) fail("cannot open HDF5 file '" + path + "': it is unreadable or corrupt (cut short by a transfer or a full disk?); copy it again or use another");
  return f;
}

Handle create_group(hid_t parent, const std::string& name) {
  Handle g(H5Gcreate2(parent, name.c_str(), H5P_DEFAULT, untimed(H5P_GROUP_CREATE), H5P_DEFAULT), H5Gclose);
  if (!g.valid()) fail("HDF5: cannot create group '" + name + "'");
  return g;
}

bool exists(hid_t parent, const std::string& name) {
  silence_errors();
  return H5Lexists(parent, name.c_str(), H5P_DEFAULT) > 0;
}

bool exists_attr(hid_t obj, const std::string& name) {
  silence_errors();
  return H5Aexists(obj, name.c_str()) > 0;
}

Handle open_group(hid_t parent, const std::string& name, const std::string& file) {
  if (!exists(parent, name)) {
    // Each kind of file named as the other is said so (a snapshot given to resume, a checkpoint to analyze).
    if (name == "Checkpoint")
      fail("'" + file + "' has no group 'Checkpoint': not an sphdisk checkpoint (resume reads the checkpoint.hdf5 a run wrote)");
    if (exists(parent, "Checkpoint"))
      fail("'" + file + "' is an sphdisk checkpoint, not a snapshot; give a snapshot_NNN.hdf5 of the run");
    fail("'" + file + "' has no group '" + name + "': not a snapshot in the sphdisk/GADGET layout");
  }
  Handle g(H5Gopen2(parent, name.c_str(), H5P_DEFAULT), H5Gclose);
  if (!g.valid()) fail("'" + file + "': cannot open group '" + name + "' (file corrupt?)");
  return g;
}

void write_attr(hid_t obj, const std::string& name, double v) { write_attr_raw(obj, name, H5T_NATIVE_DOUBLE, &v, 1, true); }
void write_attr(hid_t obj, const std::string& name, long long v) { write_attr_raw(obj, name, H5T_NATIVE_LLONG, &v, 1, true); }
void write_attr(hid_t obj, const std::string& name, const std::vector<double>& v) {
  write_attr_raw(obj, name, H5T_NATIVE_DOUBLE, v.data(), v.size(), false);
}
void write_attr(hid_t obj, const std::string& name, const std::vector<std::uint32_t>& v) {
  write_attr_raw(obj, name, H5T_NATIVE_UINT32, v.data(), v.size(), false);
}
void write_attr(hid_t obj, const std::string& name, const std::vector<std::uint64_t>& v) {
  write_attr_raw(obj, name, H5T_NATIVE_UINT64, v.data(), v.size(), false);
}
void write_attr(hid_t obj, const std::string& name, const std::string& v) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type, v.empty() ? 1 : v.size());
  H5Tset_strpad(type, H5T_STR_NULLPAD);
  write_attr_raw(obj, name, type, v.empty() ? "" : v.data(), 1, true);
}

bool has_attr(hid_t obj, const std::string& name) {
  silence_errors();
  return H5Aexists(obj, name.c_str()) > 0;
}

std::vector<double> read_attr_doubles(hid_t obj, const std::string& name, const std::string& file) {
  if (!has_attr(obj, name)) fail("'" + file + "' lacks the attribute '" + name + "'");
  Handle attr(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose);
  Handle space(H5Aget_space(attr), H5Sclose);
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  if (n <= 0 || n > (1 << 20)) fail("'" + file + "': attribute '" + name + "' has an invalid size");
  std::vector<double> v(static_cast<std::size_t>(n));
  if (H5Aread(attr, H5T_NATIVE_DOUBLE, v.data()) < 0) fail("'" + file + "': attribute '" + name + "' is not numeric");
  return v;
}

std::string read_attr_string(hid_t obj, const std::string& name, const std::string& file) {
  if (!has_attr(obj, name)) fail("'" + file + "' lacks the attribute '" + name + "'");
  Handle attr(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose);
  Handle type(H5Aget_type(attr), H5Tclose);
  if (H5Tget_class(type) != H5T_STRING) fail("'" + file + "': attribute '" + name + "' is not a string");
  if (H5Tis_variable_str(type) > 0) {  // as h5py writes a Python str
    Handle space(H5Aget_space(attr), H5Sclose);
    if (H5Sget_simple_extent_npoints(space) != 1) fail("'" + file + "': attribute '" + name + "' is not one string");
    Handle memory(H5Tcopy(H5T_C_S1), H5Tclose);
    H5Tset_size(memory, H5T_VARIABLE);
    H5Tset_cset(memory, H5Tget_cset(type));
    char* text = nullptr;
    if (H5Aread(attr, memory, &text) < 0) fail("'" + file + "': cannot read attribute '" + name + "'");
    std::string v = text != nullptr ? text : "";
    H5free_memory(text);
    return v;
  }
  const std::size_t size = H5Tget_size(type);
  if (size == 0 || size > (1u << 26)) fail("'" + file + "': attribute '" + name + "' has an invalid size");
  std::string v(size, '\0');
  if (H5Aread(attr, type, v.data()) < 0) fail("'" + file + "': cannot read attribute '" + name + "'");
  v.resize(v.find('\0') == std::string::npos ? v.size() : v.find('\0'));
  return v;
}

double read_attr_double(hid_t obj, const std::string& name, const std::string& file) {
  return read_attr_doubles(obj, name, file).front();
}

Handle create_dataset(hid_t group, const std::string& name, bool u64, std::size_t rows, std::size_t cols) {
  const hsize_t dims[2] = {rows, cols};
  Handle space(H5Screate_simple(cols == 1 ? 1 : 2, dims, nullptr), H5Sclose);
  // Space allocated at creation and never filled: what the MPI-IO driver requires, set for one process
  // too so that both write the same bytes.
  Handle props = untimed(H5P_DATASET_CREATE);
  H5Pset_alloc_time(props, H5D_ALLOC_TIME_EARLY);
  H5Pset_fill_time(props, H5D_FILL_TIME_NEVER);
  Handle ds(H5Dcreate2(group, name.c_str(), u64 ? H5T_STD_U64LE : H5T_IEEE_F64LE, space, H5P_DEFAULT, props, H5P_DEFAULT),
            H5Dclose);
  if (!ds.valid()) fail("HDF5 could not create dataset '" + name + "'");
  return ds;
}

namespace {
// Every rank of a collective transfer calls this, with rows = 0 if it has none.
void write_rows(hid_t ds, hid_t mem_type, const void* data, std::size_t first_row, std::size_t rows, std::size_t cols,
                hid_t transfer) {
  if (rows == 0 && transfer == H5P_DEFAULT) return;
  Handle file_space(H5Dget_space(ds), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(file_space);
  const hsize_t start[2] = {first_row, 0}, count[2] = {rows, cols}, one[2] = {1, cols};
  Handle mem_space(H5Screate_simple(rank, rows == 0 ? one : count, nullptr), H5Sclose);
  const bool selected = rows == 0 ? H5Sselect_none(file_space) >= 0 && H5Sselect_none(mem_space) >= 0
                                  : H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, nullptr, count, nullptr) >= 0;
  if (!selected || H5Dwrite(ds, mem_type, mem_space, file_space, transfer, data) < 0)
    fail("HDF5 could not write rows " + std::to_string(first_row) + "+" + std::to_string(rows) + " of a dataset");
}
}  // namespace

void write_rows(hid_t ds, const double* data, std::size_t first_row, std::size_t rows, std::size_t cols, hid_t transfer) {
  write_rows(ds, H5T_NATIVE_DOUBLE, data, first_row, rows, cols, transfer);
}

void write_rows(hid_t ds, const std::uint64_t* data, std::size_t first_row, std::size_t rows, hid_t transfer) {
  write_rows(ds, H5T_NATIVE_UINT64, data, first_row, rows, 1, transfer);
}

void write_dataset(hid_t group, const std::string& name, const double* data, std::size_t rows, std::size_t cols) {
  write_rows(create_dataset(group, name, false, rows, cols), data, 0, rows, cols);
}

void write_dataset(hid_t group, const std::string& name, const std::uint64_t* data, std::size_t rows) {
  write_rows(create_dataset(group, name, true, rows, 1), data, 0, rows);
}

namespace {
Handle open_dataset_shape(hid_t group, const std::string& name, const std::string& file, std::size_t& rows, std::size_t& cols,
                          RowShare share) {
  if (!exists(group, name)) fail("'" + file + "' has no dataset '" + name + "'");
  Handle ds(H5Dopen2(group, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (!ds.valid()) fail("'" + file + "': cannot open dataset '" + name + "' (file corrupt?)");
  Handle space(H5Dget_space(ds), H5Sclose);
  hsize_t dims[2] = {0, 1};
  const int rank = H5Sget_simple_extent_ndims(space);
  if (rank < 1 || rank > 2) fail("'" + file + "': dataset '" + name + "' must be 1-D or 2-D");
  H5Sget_simple_extent_dims(space, dims, nullptr);
  rows = dims[0];
  cols = rank == 2 ? dims[1] : 1;
  // A corrupt header can claim any size: refuse what could not fit in memory before allocating.
  const double bytes = static_cast<double>(share.count(rows)) * static_cast<double>(cols) * 8.0;
  const double memory = static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
  if (cols > 64 || bytes > 0.5 * memory)
    fail("'" + file + "': dataset '" + name + "' claims " + std::to_string(rows) + " x " + std::to_string(cols) +
         " values, more than this machine can hold (corrupt file?)");
  return ds;
}

// Reads the share's rows of ds into out (sized share.count(rows) x cols).
template <class T>
void read_share(hid_t ds, hid_t mem_type, std::size_t rows, std::size_t cols, RowShare share, std::vector<T>& out,
                const std::string& name, const std::string& file) {
  const std::size_t count = share.count(rows);
  out.resize(count * cols);
  if (count == 0) return;
  Handle file_space(H5Dget_space(ds), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(file_space);
  const hsize_t start[2] = {share.first(rows), 0}, shape[2] = {count, cols};
  Handle mem_space(H5Screate_simple(rank, shape, nullptr), H5Sclose);
  if (H5Sselect_hyperslab(file_space, H5S_SELECT_SET, start, nullptr, shape, nullptr) < 0 ||
      H5Dread(ds, mem_type, mem_space, file_space, H5P_DEFAULT, out.data()) < 0)
    fail("'" + file + "': cannot read dataset '" + name + "' (truncated or corrupt file?)");
}
}  // namespace

std::vector<double> read_dataset_doubles(hid_t group, const std::string& name, const std::string& file,
                                         std::size_t& rows, std::size_t& cols, RowShare share) {
  Handle ds = open_dataset_shape(group, name, file, rows, cols, share);
  std::vector<double> v;
  read_share(ds, H5T_NATIVE_DOUBLE, rows, cols, share, v, name, file);
  return v;
}

std::vector<std::uint64_t> read_dataset_u64(hid_t group, const std::string& name, const std::string& file,
                                            std::size_t& rows, RowShare share) {
  std::size_t cols;
  Handle ds = open_dataset_shape(group, name, file, rows, cols, share);
  if (cols != 1) fail("'" + file + "': dataset '" + name + "' must be 1-D");
  std::vector<std::uint64_t> v;
  read_share(ds, H5T_NATIVE_UINT64, rows, cols, share, v, name, file);
  return v;
}

}  // namespace sphdisk::h5
