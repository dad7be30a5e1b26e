// Helpers shared by session's tests: a private temporary directory, whole-file access, and the inputs of
// a small session.
#pragma once

#include <string>

#include <gtest/gtest.h>

#include "session/session_dir.h"
#include "support/temp_files.h"

namespace selfcal::session::testing {

inline constexpr char kTempDirPrefix[] = "selfcal_session_test";
using TempDir = selfcal::testing::NamedTempDir<kTempDirPrefix>;
using namespace selfcal::testing;  // ReadFile, WriteFile and the other helpers of temp_files.h

inline bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

inline SessionInputs TestInputs() {
  return {{"config.yaml", "mode: simulated\n"}, {"robot.yaml", "name: puma560\n"}, {"plan.yaml", "poses: []\n"}};
}

inline CreateOptions TestCreateOptions() {
  CreateOptions options;
  options.created_utc = "2025-03-01T12:00:00Z";
  return options;
}

// A new session at `path` with TestInputs(); fails the test (and returns an error) when it cannot.
inline Result<Session> CreateTestSession(const std::string& path) {
  Result<Session> session = CreateSession(path, TestInputs(), "selfcal 0.1.0-test", TestCreateOptions());
  EXPECT_TRUE(session.ok()) << session.status().ToString();
  return session;
}

}  // namespace selfcal::session::testing
