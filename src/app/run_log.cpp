#include "app/run_log.hpp"

#include <unistd.h>

#include <cstdarg>
#include <ctime>
#include <filesystem>

#include "core/build_info.hpp"
#include "core/error.hpp"
#include "core/vector_isa.hpp"

namespace sphdisk::run_log {

namespace {
std::FILE* g_log = nullptr;

// Local time with its UTC offset, e.g. 2026-12-04T16:39:05+0100.
std::string now_text() {
  const std::time_t t = std::time(nullptr);
  std::tm local{};
  localtime_r(&t, &local);
  char buf[40];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%S%z", &local);
  return buf;
}
}  // namespace

void open(const std::string& dir) {
  close();
  const std::string path = (std::filesystem::path(dir) / kName).string();
  g_log = std::fopen(path.c_str(), "a");
  if (!g_log) throw UserError("cannot write '" + path + "'; check the output directory's permissions");
}

void close() {
  if (g_log) std::fclose(g_log);
  g_log = nullptr;
}

// A failed write (full disk) is not reported here: the outputs that hold the results report theirs.
void write(const std::string& text) {
  if (!g_log) return;
  std::fputs(text.c_str(), g_log);
  std::fflush(g_log);
}

void print(std::FILE* terminal, const char* format, ...) {
  std::va_list args, again;
  va_start(args, format);
  va_copy(again, args);
  const int n = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  std::string text(n > 0 ? static_cast<std::size_t>(n) : 0, '\0');
  if (n > 0) std::vsnprintf(text.data(), text.size() + 1, format, again);
  va_end(again);
  if (terminal) std::fputs(text.c_str(), terminal);
  write(text);
}

std::string header(const std::string& what, const std::string& command_line, int ranks, int threads) {
  char host[256] = "?";
  gethostname(host, sizeof host - 1);
  std::error_code ec;
  const std::string cwd = std::filesystem::current_path(ec).string();
  return "==== sphdisk " + what + ", started " + now_text() + " ====\n" +
         "command: " + command_line + "\n" +
         "working directory: " + cwd + "\n" +
         "code version: " + std::string(code_version()) + "\n" +
         "build: " + build_options() + "\n" +
         "host: " + host + "\n" +
         "ranks: " + std::to_string(ranks) + ", threads: " + std::to_string(threads) + " per rank, vector loops: " +
         vector_isa_name(vector_isa()) + "\n";
}

std::string format_duration(double s) {
  char buf[32];
  if (s < 60) std::snprintf(buf, sizeof buf, "%.0fs", s);
  else if (s < 3600) std::snprintf(buf, sizeof buf, "%dm%02ds", int(s / 60), int(s) % 60);
  else std::snprintf(buf, sizeof buf, "%dh%02dm", int(s / 3600), int(s / 60) % 60);
  return buf;
}

}  // namespace sphdisk::run_log
