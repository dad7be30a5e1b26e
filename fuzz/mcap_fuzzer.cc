// Fuzz harness: a ROS 2 recording (rosbag2 MCAP, docs/detect.md "ROS 2 recordings") through the reader of
// `selfcal detect --bag`: rosbag::ParseMcap, then every kept message decoded as the type its topic holds
// (JointState; Image made grey, bounded to small images). Any crash, sanitizer report, hang or uncaught
// exception is a defect; a refusal is the expected answer to a bad file and should name `fuzz.mcap: byte N`.
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz/fuzz_support.h"
#include "rosbag/mcap_reader.h"
#include "rosbag/ros_messages.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace selfcal::rosbag;  // NOLINT
  McapLimits limits;
  limits.max_chunk_bytes = 8u << 20;
  limits.max_kept_bytes = 16u << 20;
  const selfcal::Result<McapContents> bag =
      ParseMcap(selfcal::fuzz::AsText(data, size), "fuzz.mcap", {"/joint_states", "/camera/image_raw"}, limits);
  if (!bag.ok()) {
    selfcal::fuzz::NoteRefusal("mcap", bag.status().message(), "fuzz.mcap: byte ");
    return 0;
  }
  for (const McapMessage& m : bag->messages) {
    if (bag->channels.at(m.channel_id).topic == "/joint_states") {
      const selfcal::Result<JointStateMessage> joints = DecodeJointState(m.data, m.where);
      if (!joints.ok()) selfcal::fuzz::NoteRefusal("mcap", joints.status().message(), "fuzz.mcap: byte ");
      continue;
    }
    const selfcal::Result<ImageMessage> image = DecodeImage(m.data, m.where);
    if (!image.ok()) {
      selfcal::fuzz::NoteRefusal("mcap", image.status().message(), "fuzz.mcap: byte ");
      continue;
    }
    const auto grey = GreyImage(*image, m.where, 1u << 16);
    if (!grey.ok()) selfcal::fuzz::NoteRefusal("mcap", grey.status().message(), "fuzz.mcap: byte ");
  }
  return 0;
}
