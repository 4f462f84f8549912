// Fuzz target: any bytes given as a snapshot or checkpoint file must be read or refused with
// UserError; never crash or raise anything else.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "core/error.hpp"
#include "io/checkpoint.hpp"
#include "io/snapshot.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  // One file per process (parallel fuzzing), its name always as long (the pid zero-padded): the
  // name's length shows in the readers' error paths, and a varying one made runs take different
  // paths (tests/fuzz/short_fuzz_run.sh needs the same run every time).
  static const std::string path = [] {
    char name[64];
    std::snprintf(name, sizeof name, "/tmp/sphdisk_fuzz_%010ld.hdf5", static_cast<long>(::getpid()));
    return std::string(name);
  }();
  FILE* f = std::fopen(path.c_str(), "wb");
  if (!f) return 0;
  std::fwrite(data, 1, size, f);
  std::fclose(f);
  try {
    sphdisk::SnapshotMeta meta;
    sphdisk::read_snapshot<2>(path, nullptr, meta);
  } catch (const sphdisk::UserError&) {
  }
  try {
    sphdisk::RunState s;
    sphdisk::read_checkpoint<2>(path, s);
  } catch (const sphdisk::UserError&) {
  }
  return 0;
}
