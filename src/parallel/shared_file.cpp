#include "parallel/shared_file.hpp"

#include <stdexcept>

#ifdef SPHDISK_HAVE_MPI
#include <mpi.h>
#ifndef H5_HAVE_PARALLEL
#error "SPHDISK_MPI needs HDF5's parallel flavour (Debian: libhdf5-openmpi-dev)"
#endif
#endif

namespace sphdisk {

hid_t shared_file_access(const Communicator& comm) {
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
#ifdef SPHDISK_HAVE_MPI
  if (comm.size() > 1) {
    const MPI_Comm mpi = *static_cast<MPI_Comm*>(comm.native_handle());
    if (H5Pset_fapl_mpio(fapl, mpi, MPI_INFO_NULL) < 0) throw std::runtime_error("H5Pset_fapl_mpio failed");
  }
#else
  (void)comm;
#endif
  return fapl;
}

hid_t shared_transfer(const Communicator& comm) {
  const hid_t dxpl = H5Pcreate(H5P_DATASET_XFER);
#ifdef SPHDISK_HAVE_MPI
  // Collective: the MPI-IO layer merges the ranks' rows into large contiguous writes.
  if (comm.size() > 1 && H5Pset_dxpl_mpio(dxpl, H5FD_MPIO_COLLECTIVE) < 0)
    throw std::runtime_error("H5Pset_dxpl_mpio failed");
#else
  (void)comm;
#endif
  return dxpl;
}

}  // namespace sphdisk
