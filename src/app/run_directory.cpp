#include "app/run_directory.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "app/run_log.hpp"
#include "core/error.hpp"
#include "io/atomic_file.hpp"

namespace sphdisk {

namespace fs = std::filesystem;

std::string snapshot_name(const std::string& dir, std::size_t k) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "snapshot_%03zu.hdf5", k);
  return (fs::path(dir) / buf).string();
}

// Refuses to replace results of an earlier run unless asked; checks the directory is writable.
void prepare_output_dir(const std::string& dir, bool overwrite) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw UserError("cannot create output directory '" + dir + "': " + ec.message() + "; choose another with --output");
  // One pass over the directory: an earlier run's first result file, and whether it holds a run's
  // log and a config.toml.
  std::string result;
  bool log = false, config_toml = false;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (result.empty() && (name.rfind("snapshot_", 0) == 0 || name == kDiagnosticsName || name == kCheckpointName)) result = name;
    log = log || name == run_log::kName;
    config_toml = config_toml || name == "config.toml";
  }
  // A config.toml with nothing of a run beside it (no log, diagnostics, snapshot or checkpoint) is
  // the user's own file (say the configuration being run), which the run's resolved config.toml
  // would replace, and --overwrite remove.
  if (config_toml && result.empty() && !log)
    throw UserError("output directory '" + dir + "' holds a config.toml that no run wrote (no run's files beside it), "
                    "which the run would replace with its resolved settings; write the run elsewhere with --output, "
                    "or move the file");
  if (!overwrite && !result.empty())
    throw UserError("output directory '" + dir + "' already holds results (" + result +
                    "); use --output for a new directory, --overwrite to replace them, or `sphdisk resume " + dir +
                    "` to continue");
  const std::string probe = (fs::path(dir) / ".sphdisk_write_test").string();
  std::ofstream f(probe);
  if (!f || !(f << "x") || (f.close(), !f)) throw UserError("output directory '" + dir + "' is not writable; choose another with --output");
  fs::remove(probe, ec);
}

// What a run writes into its directory (and `sphdisk report` beside it): with --overwrite all of it
// goes before the new run writes anything, so two runs' outputs never mix (a stale snapshot_004 of a
// longer earlier run would otherwise sit beside the new run's three). Files of other names stay.
bool written_by_a_run(const std::string& name) {
  const auto starts = [&](const char* prefix) { return name.rfind(prefix, 0) == 0; };
  const auto ends = [&](const char* suffix) {
    const std::string s(suffix);
    return name.size() >= s.size() && name.compare(name.size() - s.size(), s.size(), s) == 0;
  };
  return (starts("snapshot_") && ends(".hdf5")) || (starts("debug_step_") && ends(".hdf5")) || starts(kCheckpointName) ||
         name == kDiagnosticsName || name == "config.toml" || name == "timers.json" || name == "ranks.json" ||
         name == run_log::kName || name == "report";
}

void remove_earlier_run(const std::string& dir) {
  std::vector<fs::path> old;
  for (const auto& e : fs::directory_iterator(dir))
    if (written_by_a_run(e.path().filename().string())) old.push_back(e.path());
  for (const auto& path : old) {
    std::error_code ec;
    fs::remove_all(path, ec);
    if (ec)
      throw UserError("--overwrite: cannot remove '" + path.string() + "' of the earlier run (" + ec.message() +
                      "); remove it by hand or choose another directory with --output");
  }
}

void write_text_file(const std::string& dir, const std::string& name, const std::string& text) {
  write_text_atomically((fs::path(dir) / name).string(), text);
}

void truncate_diagnostics(const std::string& dir, long long step) {
  const std::string path = (fs::path(dir) / kDiagnosticsName).string();
  std::ifstream in(path);
  std::ostringstream kept;
  std::string line;
  bool header = true;
  while (std::getline(in, line)) {
    if (!header) {
      const long long row_step = std::atoll(line.c_str());
      if (row_step > step || line.find(',') == std::string::npos) break;
    }
    kept << line << '\n';
    header = false;
  }
  if (header) kept << kDiagnosticsHeader << '\n';
  write_text_file(dir, kDiagnosticsName, kept.str());
}

}  // namespace sphdisk
