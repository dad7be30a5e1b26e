#include "fuzz/fuzz_support.h"

#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace selfcal::fuzz {
namespace {

struct RefusalCounts {
  std::string harness;
  long refusals = 0;
  long with_line = 0;
  ~RefusalCounts() {
    const char* stats = std::getenv("SELFCAL_FUZZ_STATS");
    if (stats == nullptr || *stats == '\0' || harness.empty()) return;
    if (FILE* out = std::fopen(stats, "a")) {
      std::fprintf(out, "%s refusals=%ld with_line=%ld\n", harness.c_str(), refusals, with_line);
      std::fclose(out);
    }
  }
};

RefusalCounts& Counts() {
  static RefusalCounts counts;
  return counts;
}

struct TempDir {
  std::string path;
  TempDir() {
    std::string pattern = (std::filesystem::temp_directory_path() / "selfcal-fuzz-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) {
      std::perror("selfcal fuzz: mkdtemp");
      std::abort();
    }
    path = pattern;
  }
  ~TempDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path, ignored);
  }
};

bool NamesLine(const std::string& message, const std::string& key) {
  for (size_t at = message.find(key); at != std::string::npos; at = message.find(key, at + 1)) {
    const size_t digit = at + key.size();
    if (digit < message.size() && std::isdigit(static_cast<unsigned char>(message[digit]))) return true;
  }
  return false;
}

}  // namespace

const std::string& FuzzDir() {
  static TempDir dir;
  return dir.path;
}

std::string WriteFuzzFile(const std::string& name, const std::string& bytes) {
  const std::string path = FuzzDir() + "/" + name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) {
    std::fprintf(stderr, "selfcal fuzz: cannot write %s\n", path.c_str());
    std::abort();
  }
  return path;
}

void NoteRefusal(const char* harness, const std::string& message, const std::string& line_prefix) {
  static const bool enabled = std::getenv("SELFCAL_FUZZ_STATS") != nullptr;
  if (!enabled) return;
  RefusalCounts& counts = Counts();
  counts.harness = harness;
  ++counts.refusals;
  if (NamesLine(message, line_prefix)) {
    ++counts.with_line;
  } else if (std::getenv("SELFCAL_FUZZ_SHOW") != nullptr) {
    std::fprintf(stderr, "refusal without a line: %s\n", message.c_str());
  }
}

}  // namespace selfcal::fuzz
