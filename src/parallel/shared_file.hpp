#pragma once
// HDF5 property lists for one file written by all ranks of a communicator at once: the MPI-IO file
// driver and collective transfers, so that every rank writes its own rows and none gathers another
// rank's particles (the paper's T3E code, and our first MPI version, funnelled output through one
// node). For a communicator of one rank: the default POSIX driver and independent transfers.
#include <hdf5.h>

#include "parallel/communicator.hpp"

namespace sphdisk {

// New property lists; the caller closes them (H5Pclose).
hid_t shared_file_access(const Communicator& comm);
hid_t shared_transfer(const Communicator& comm);

}  // namespace sphdisk
