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
  static const std::string path = "/tmp/sphdisk_fuzz_" + std::to_string(::getpid()) + ".hdf5";
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
    sphdisk::read_checkpoint(path, s);
  } catch (const sphdisk::UserError&) {
  }
  return 0;
}
