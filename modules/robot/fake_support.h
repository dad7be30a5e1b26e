// Internal to robot: what the loopback controller fakes (ur_fake.h, fanuc_fake.h) share.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <utility>

#include "robot/line_socket.h"

namespace selfcal::robot::internal {

// Where a fake tells what it saw and did; may be empty (nothing is told).
using FakeLog = std::function<void(const std::string&)>;

inline void Say(const FakeLog& log, const std::string& line) {
  if (log) log(line);
}

// A client waiting on `listener` becomes `client`, replacing (closing) the one before, and is sent
// `greeting` when there is one; true when a client was taken.
inline bool AcceptNewest(TcpListener* listener, LineSocket* client, const std::string& greeting = "") {
  std::optional<LineSocket> waiting = listener->Accept(0, 4096);
  if (!waiting) return false;
  *client = std::move(*waiting);
  if (!greeting.empty()) client->WriteLine(greeting, 0.5);
  return true;
}

}  // namespace selfcal::robot::internal
