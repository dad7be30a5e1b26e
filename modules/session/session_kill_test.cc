// P1, P2: a session process killed (SIGKILL) at random moments loses no acknowledged record, leaves no
// corrupt record and no record naming a missing or damaged image.
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include <cstdint>
#include <random>

#include <gtest/gtest.h>

#include "base/atomic_file.h"
#include "base/crc32.h"
#include "session/session_dir.h"
#include "session/session_test_util.h"

namespace selfcal::session {
namespace {

using testing::CreateTestSession;
using testing::TempDir;
using testing::TestInputs;

// Deterministic image bytes for record `index`, 1-4 KiB.
std::string ImageBytes(std::size_t index) {
  std::string bytes(1024 + (index * 997) % 3072, '\0');
  for (std::size_t i = 0; i < bytes.size(); ++i) bytes[i] = static_cast<char>((i * 31 + index * 7) & 0xFF);
  return bytes;
}

// The child: resumes the session, then forever writes an image, appends the record naming it and reports
// the number of durable appends of this run on `report_fd` (4 bytes, atomic on a pipe). Exit codes > 0
// say what failed; a SIGKILL ends it normally.
[[noreturn]] void RunChild(const std::string& path, int report_fd) {
  Result<Session> opened = OpenSession(path, TestInputs(), false);
  if (!opened.ok()) ::_exit(20);
  Session& session = opened.value();
  std::uint32_t acknowledged = 0;
  for (std::size_t index = session.journal().records().size();; ++index) {
    const std::string name = "frame_" + std::to_string(index) + ".bin";
    const std::string bytes = ImageBytes(index);
    if (!session.WriteImage(name, bytes).ok()) ::_exit(21);
    const nlohmann::json record = {{"type", "frame_written"},
                                   {"image", ImageRecordPath(name)},
                                   {"crc32", Crc32Hex(Crc32(bytes))},
                                   {"bytes", bytes.size()},
                                   {"index", index}};
    if (!session.journal().Append(record).ok()) ::_exit(22);
    ++acknowledged;
    if (::write(report_fd, &acknowledged, sizeof(acknowledged)) != sizeof(acknowledged)) ::_exit(23);
  }
}

// The last count the child reported before it died (0 when none).
std::uint32_t LastReported(int fd) {
  std::uint32_t last = 0, value = 0;
  while (::read(fd, &value, sizeof(value)) == static_cast<ssize_t>(sizeof(value))) last = value;
  return last;
}

TEST(SessionKillTest, SigkillAtRandomMomentsKeepsEveryAcknowledgedRecord) {
  TempDir dir;
  const std::string path = dir.File("s");
  ASSERT_TRUE(CreateTestSession(path).ok());
  std::mt19937 rng(20250301);
  std::uniform_int_distribution<long> delay_ns(0, 20'000'000);
  std::size_t durable = 0;  // records known durable before the current child started
  int kills_with_progress = 0;
  // 30 kills, and more (with longer delays) until one came after acknowledged records: on a loaded machine
  // a child may not write anything within 20 ms thirty times in a row.
  for (int run = 0; run < 300 && (run < 30 || durable == 0 || kills_with_progress == 0); ++run) {
    SCOPED_TRACE("run " + std::to_string(run));
    int pipe_fds[2];
    ASSERT_EQ(::pipe2(pipe_fds, O_CLOEXEC), 0);
    const long stretch = 1 + run / 30;  // up to 200 ms after 270 kills without progress
    const long ns = delay_ns(rng) * stretch;
    const timespec delay{ns / 1'000'000'000, ns % 1'000'000'000};
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(pipe_fds[0]);
      RunChild(path, pipe_fds[1]);
    }
    ::close(pipe_fds[1]);
    ::nanosleep(&delay, nullptr);
    ASSERT_EQ(::kill(child, SIGKILL), 0);
    int status = 0;
    ASSERT_EQ(::waitpid(child, &status, 0), child);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the child exited with " << WEXITSTATUS(status) << " before the kill";
    const std::uint32_t acknowledged = LastReported(pipe_fds[0]);
    ::close(pipe_fds[0]);
    if (acknowledged > 0) ++kills_with_progress;

    Result<Session> session = OpenSession(path, TestInputs(), false, JournalLimits(), /*take_over_stale_lock=*/true);
    ASSERT_TRUE(session.ok()) << session.status().ToString();
    const std::string& stale = session->open_report().stale_lock_from;
    if (!stale.empty()) {
      EXPECT_EQ(stale.substr(0, stale.find(' ')), std::to_string(child));
    }
    const std::vector<nlohmann::json>& records = session->journal().records();
    ASSERT_GE(records.size(), durable + acknowledged);
    for (std::size_t i = 0; i < records.size(); ++i) {
      const nlohmann::json& record = records[i];
      ASSERT_EQ(record["index"], i);  // in order, none lost in the middle
      Result<std::string> image = ReadFileCapped(path + "/" + record["image"].get<std::string>(), 1 << 20);
      ASSERT_TRUE(image.ok()) << image.status().ToString();
      EXPECT_EQ(image->size(), record["bytes"].get<std::size_t>());
      EXPECT_EQ(Crc32Hex(Crc32(*image)), record["crc32"]);
    }
    durable = records.size();
  }
  EXPECT_GT(durable, 0u);
  EXPECT_GT(kills_with_progress, 0);
}

}  // namespace
}  // namespace selfcal::session
