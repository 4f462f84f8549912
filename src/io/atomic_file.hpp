#pragma once
// Outputs appear whole or not at all: every file is written under a temporary name, flushed to
// disk and renamed over the final name, so a crash, a kill or a full disk never leaves a partial
// file that looks valid, and the previous version stays until the new one is complete.
#include <hdf5.h>

#include <functional>
#include <string>

#include "parallel/communicator.hpp"

namespace sphdisk {

// fsync tmp_path, rename it to final_path, fsync the directory. Removes tmp_path on failure.
void publish_file(const std::string& tmp_path, const std::string& final_path);

// Creates an HDF5 file at path + ".tmp", lets fill() write into it, flushes and publishes it.
// Any failure removes the temporary file and becomes one UserError naming path and the fix.
void write_hdf5_atomically(const std::string& path, const std::function<void(hid_t file)>& fill);

// The same for one file written by all ranks of comm together (collective: every rank calls it
// with the same metadata; fill writes this rank's rows with the transfer list it is given). A
// failure anywhere is a UserError on rank 0 and a PeerError on the others; rank 0 publishes.
using ShareFill = std::function<void(hid_t file, hid_t transfer)>;
void write_hdf5_atomically(const std::string& path, const Communicator& comm, const ShareFill& fill);

// The same for a text file.
void write_text_atomically(const std::string& path, const std::string& text);

}  // namespace sphdisk
