#pragma once
// Outputs appear whole or not at all: every file is written under a temporary name, flushed to
// disk and renamed over the final name, so a crash, a kill or a full disk never leaves a partial
// file that looks valid, and the previous version stays until the new one is complete.
#include <hdf5.h>

#include <functional>
#include <string>

namespace sphdisk {

// fsync tmp_path, rename it to final_path, fsync the directory. Removes tmp_path on failure.
void publish_file(const std::string& tmp_path, const std::string& final_path);

// Creates an HDF5 file at path + ".tmp", lets fill() write into it, flushes and publishes it.
// Any failure removes the temporary file and becomes one UserError naming path and the fix.
void write_hdf5_atomically(const std::string& path, const std::function<void(hid_t file)>& fill);

// The same for a text file.
void write_text_atomically(const std::string& path, const std::string& text);

}  // namespace sphdisk
