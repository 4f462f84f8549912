#include "io/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "io/hdf5_util.hpp"
#include "parallel/shared_file.hpp"

namespace sphdisk {
namespace {
[[noreturn]] void fail_writing(const std::string& path, const std::string& why) {
  throw UserError("cannot write '" + path + "': " + why + "; free disk space or choose another output directory (-o)");
}
}  // namespace

void publish_file(const std::string& tmp_path, const std::string& final_path) {
  const int fd = ::open(tmp_path.c_str(), O_RDONLY);
  if (fd < 0 || ::fsync(fd) != 0) {
    if (fd >= 0) ::close(fd);
    std::remove(tmp_path.c_str());
    fail_writing(final_path, "flushing '" + tmp_path + "' to disk failed");
  }
  ::close(fd);
  if (std::rename(tmp_path.c_str(), final_path.c_str()) != 0) {
    std::remove(tmp_path.c_str());
    fail_writing(final_path, "renaming '" + tmp_path + "' failed");
  }
  const std::string dir = std::filesystem::path(final_path).parent_path().string();
  const int dfd = ::open(dir.empty() ? "." : dir.c_str(), O_RDONLY | O_DIRECTORY);
  if (dfd >= 0) {
    ::fsync(dfd);
    ::close(dfd);
  }
}

void write_hdf5_atomically(const std::string& path, const Communicator& comm, const ShareFill& fill) {
  const std::string tmp = path + ".tmp";
  try {
    run_collectively(comm, [&] {
      h5::Handle access(shared_file_access(comm), H5Pclose);
      h5::Handle transfer(shared_transfer(comm), H5Pclose);
      h5::Handle file = h5::create_file(tmp, access);
      fill(file, transfer);
      if (H5Fflush(file, H5F_SCOPE_GLOBAL) < 0) throw UserError("HDF5 could not flush the file");
    });  // the file is closed (collectively) before anyone publishes it
  } catch (const UserError& e) {  // on rank 0 (the others throw PeerError)
    std::remove(tmp.c_str());
    fail_writing(path, e.what());
  } catch (const PeerError&) {
    throw;
  } catch (...) {
    if (comm.is_root()) std::remove(tmp.c_str());
    throw;
  }
  run_on_root(comm, [&] { publish_file(tmp, path); });
}

void write_hdf5_atomically(const std::string& path, const std::function<void(hid_t file)>& fill) {
  write_hdf5_atomically(path, Communicator::self(), [&fill](hid_t file, hid_t) { fill(file); });
}

void write_text_atomically(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp);
    f << text;
    if (!f.flush()) {
      std::remove(tmp.c_str());
      fail_writing(path, "the text could not be written");
    }
  }
  publish_file(tmp, path);
}

}  // namespace sphdisk
