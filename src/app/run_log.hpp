#pragma once
// run.log in a run directory (docs/formats.md, "Run directory"): where each `run` and `resume` came
// from (command, code version, build, threads, ranks, start time), then the lines it printed on the
// terminal (progress, summary, errors), so that the record stays with the results. Only the run's
// root process writes it; every write is flushed, so a run killed at any moment leaves all it wrote.
#include <cstdio>
#include <string>

namespace sphdisk::run_log {

inline constexpr const char* kName = "run.log";

// Opens DIR/run.log for appending (closing any log open before).
void open(const std::string& dir);
void close();

// Appends text and flushes it; nothing when no log is open.
void write(const std::string& text);

// Formats like printf and prints to `terminal` (none when null) and to the log.
void print(std::FILE* terminal, const char* format, ...) __attribute__((format(printf, 2, 3)));

// The block that opens one command's part of the log: a separator line naming `what` ("run",
// "resume from step 120 (tau 0.0300)") and the time, then the command line, working directory, code
// version, build options, host, ranks, threads and vector loops.
std::string header(const std::string& what, const std::string& command_line, int ranks, int threads);

// A duration for a progress line's ETA: "42s", "3m07s", "2h05m".
std::string format_duration(double seconds);

}  // namespace sphdisk::run_log
