#include "rosbag/bag_images.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "io/robot_origin.h"
#include "rosbag/mcap_reader.h"
#include "rosbag/ros_messages.h"

namespace selfcal::rosbag {

namespace {

constexpr const char* kJointStateType = "sensor_msgs/msg/JointState";
constexpr const char* kImageType = "sensor_msgs/msg/Image";
constexpr const char* kCompressedImageType = "sensor_msgs/msg/CompressedImage";

std::string Joined(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
  return out.empty() ? "none" : out;
}

// The schema of `topic`'s channels (one type for all of them), checked against `types`.
Result<std::string> TopicType(const McapContents& bag, const std::string& path, const std::string& topic,
                              const std::vector<std::string>& types, const char* option) {
  std::string type;
  std::vector<std::string> topics;
  for (const auto& [id, channel] : bag.channels) {
    topics.push_back(channel.topic + " (" + (channel.schema_name.empty() ? "no schema" : channel.schema_name) + ")");
    if (channel.topic != topic) continue;
    if (channel.message_encoding != "cdr") {
      return Status::InvalidInput(path + ": topic " + topic + " is encoded `" + channel.message_encoding +
                                  "`, not cdr: not a ROS 2 recording");
    }
    if (std::find(types.begin(), types.end(), channel.schema_name) == types.end()) {
      return Status::InvalidInput(path + ": topic " + topic + " holds " + channel.schema_name + ", not " +
                                  Joined(types) + " (" + option + ")");
    }
    type = channel.schema_name;
  }
  if (type.empty())
    return Status::InvalidInput(path + ": no topic " + topic + " (" + option + "); the bag holds " + Joined(topics));
  return type;
}

double MessageTime(const RosStamp& stamp, std::uint64_t log_time_ns) {
  return stamp.zero() ? 1e-9 * static_cast<double>(log_time_ns) : stamp.seconds();
}

// A joint state's positions in the robot's order.
Result<Eigen::VectorXd> RobotOrder(const JointStateMessage& m, const std::string& where, int dof,
                                   const std::vector<std::string>& joint_names) {
  Eigen::VectorXd q(dof);
  if (joint_names.empty()) {
    if (static_cast<int>(m.position.size()) != dof) {
      return Status::InvalidInput(where + ": joint state of " + std::to_string(m.position.size()) +
                                  " positions for a robot of " + std::to_string(dof) +
                                  " joints (its config names no joints to pick them by)");
    }
    for (int j = 0; j < dof; ++j) q[j] = m.position[static_cast<size_t>(j)];
    return q;
  }
  if (m.position.size() != m.name.size()) {
    return Status::InvalidInput(where + ": joint state of " + std::to_string(m.name.size()) + " names and " +
                                std::to_string(m.position.size()) + " positions");
  }
  for (int j = 0; j < dof; ++j) {
    auto it = std::find(m.name.begin(), m.name.end(), joint_names[static_cast<size_t>(j)]);
    if (it == m.name.end()) {
      return Status::InvalidInput(where + ": joint state without the robot's joint `" +
                                  joint_names[static_cast<size_t>(j)] + "` (it names " + Joined(m.name) + ")");
    }
    q[j] = m.position[static_cast<size_t>(it - m.name.begin())];
  }
  return q;
}

Result<std::vector<JointSample>> ReadJoints(const McapContents& bag, const std::string& path, const BagOptions& options,
                                            int dof, const std::vector<std::string>& joint_names,
                                            std::vector<std::string>* notes) {
  std::vector<JointSample> joints;
  std::vector<std::string> first_names;
  for (const McapMessage& message : bag.messages) {
    if (bag.channels.at(message.channel_id).topic != options.joint_topic) continue;
    Result<JointStateMessage> m = DecodeJointState(message.data, message.where);
    if (!m.ok()) return m.status();
    Result<Eigen::VectorXd> q = RobotOrder(*m, message.where, dof, joint_names);
    if (!q.ok()) return q.status();
    if (!q->allFinite())
      return Status::InvalidInput(message.where + ": joint state with a position that is not a finite number");
    if (joints.empty()) first_names = m->name;
    joints.push_back({MessageTime(m->stamp, message.log_time_ns), *q});
  }
  if (joints.empty()) return Status::InvalidInput(path + ": no message on the joint topic " + options.joint_topic);
  if (joint_names.empty()) {
    notes->push_back(path + ": the robot config names no joints: the joint states' positions are taken in the "
                     "message's order (" + Joined(first_names) + ") as the robot's joints 1 to " + std::to_string(dof));
  }
  std::stable_sort(joints.begin(), joints.end(),
                   [](const JointSample& a, const JointSample& b) { return a.time_s < b.time_s; });
  return joints;
}

}  // namespace

std::vector<int> MatchStillImages(const std::vector<JointSample>& joints, const std::vector<double>& image_times_s,
                                  const BagOptions& options, int* moving, std::vector<std::string>* notes) {
  std::vector<int> matched;
  *moving = 0;
  const auto before = [](const JointSample& s, double t) { return s.time_s < t; };
  const auto after = [](double t, const JointSample& s) { return t < s.time_s; };
  for (double t : image_times_s) {
    const auto lo = std::lower_bound(joints.begin(), joints.end(), t - options.still_window_s, before);
    const auto hi = std::upper_bound(joints.begin(), joints.end(), t + options.still_window_s, after);
    bool still = lo != hi && lo->time_s <= t - 0.5 * options.still_window_s &&
                 std::prev(hi)->time_s >= t + 0.5 * options.still_window_s;
    if (still) {
      Eigen::VectorXd low = lo->position_rad, high = lo->position_rad;
      for (auto it = lo; it != hi; ++it) {
        low = low.cwiseMin(it->position_rad);
        high = high.cwiseMax(it->position_rad);
      }
      still = ((high - low).array() < options.still_tolerance_rad).all();
    }
    if (!still) {
      ++*moving;
      matched.push_back(-1);
      continue;
    }
    const auto next = std::lower_bound(joints.begin(), joints.end(), t, before);
    auto nearest = next;
    if (next == joints.end() || (next != joints.begin() && t - std::prev(next)->time_s < next->time_s - t)) {
      nearest = std::prev(next);
    }
    const double gap = std::abs(nearest->time_s - t);
    if (gap > options.match_tolerance_s) {
      char line[160];
      std::snprintf(line, sizeof(line), "the image at %.6f s is left out: its nearest joint reading is %.3f s away "
                    "(at most %.3f s)", t, gap, options.match_tolerance_s);
      notes->push_back(line);
      matched.push_back(-1);
      continue;
    }
    matched.push_back(static_cast<int>(nearest - joints.begin()));
  }
  return matched;
}

Result<BagImages> LoadBagImages(const std::string& bag, const BagOptions& options, int dof,
                                const std::vector<std::string>& joint_names) {
  if (!joint_names.empty() && static_cast<int>(joint_names.size()) != dof) {
    return Status::Error(ErrorCode::kInternal, "LoadBagImages: joint names and joint count differ");
  }
  Result<McapContents> contents = ReadMcap(bag, {options.joint_topic, options.image_topic});
  if (!contents.ok()) return contents.status();
  Result<std::string> joint_type = TopicType(*contents, bag, options.joint_topic, {kJointStateType}, "--joint-topic");
  if (!joint_type.ok()) return joint_type.status();
  Result<std::string> image_type =
      TopicType(*contents, bag, options.image_topic, {kImageType, kCompressedImageType}, "--image-topic");
  if (!image_type.ok()) return image_type.status();
  BagImages out;
  Result<std::vector<JointSample>> joints = ReadJoints(*contents, bag, options, dof, joint_names, &out.notes);
  if (!joints.ok()) return joints.status();

  std::vector<ImageMessage> images;
  std::vector<const McapMessage*> records;
  std::vector<double> times;
  for (const McapMessage& message : contents->messages) {
    if (contents->channels.at(message.channel_id).topic != options.image_topic) continue;
    Result<ImageMessage> m = *image_type == kImageType ? DecodeImage(message.data, message.where)
                                                       : DecodeCompressedImage(message.data, message.where);
    if (!m.ok()) return m.status();
    times.push_back(MessageTime(m->stamp, message.log_time_ns));
    images.push_back(std::move(*m));
    records.push_back(&message);
  }
  out.image_messages = static_cast<int>(images.size());
  const std::vector<int> matched = MatchStillImages(*joints, times, options, &out.moving, &out.notes);
  for (size_t i = 0; i < images.size(); ++i) {
    if (matched[i] < 0) continue;
    Result<vpImage<unsigned char>> grey = GreyImage(images[i], records[i]->where);
    if (!grey.ok()) return grey.status();
    if (!out.images.empty() && (grey->getWidth() != out.images[0].image.getWidth() ||
                                grey->getHeight() != out.images[0].image.getHeight())) {
      return Status::InvalidInput(records[i]->where + ": image of " + std::to_string(grey->getWidth()) + "x" +
                                  std::to_string(grey->getHeight()) + ", the first still image is " +
                                  std::to_string(out.images[0].image.getWidth()) + "x" +
                                  std::to_string(out.images[0].image.getHeight()));
    }
    char id[32];
    std::snprintf(id, sizeof(id), "image_%04zu", i);
    const std::string name = bag + ":" + options.image_topic + "#" + std::to_string(i);
    out.images.push_back({name, std::move(*grey)});
    out.inputs.images.push_back(name);
    out.inputs.ids.push_back(id);
    io::ImagePose pose;
    pose.key = id;
    pose.source = records[i]->where;
    pose.joints_rad = (*joints)[static_cast<size_t>(matched[i])].position_rad;
    out.inputs.poses.push_back(pose);
  }
  if (out.images.empty()) {
    return Status::InvalidInput(bag + ": none of the " + std::to_string(images.size()) + " images on " +
                                options.image_topic + " was taken while the arm was still (" +
                                std::to_string(out.moving) +
                                " while moving; still: no joint "
                                "moving more than the tolerance within the window either side, docs/detect.md)");
  }
  return out;
}

Result<BagImages> LoadBagImagesForRobot(const std::string& bag, const BagOptions& options,
                                        const std::string& robot_config, const RobotModel& robot) {
  Result<io::RobotOrigin> origin = io::RobotOriginOfConfig(robot_config);
  if (!origin.ok()) return origin.status();
  std::vector<std::string> names = origin->joint_names;
  if (static_cast<int>(names.size()) != robot.num_joints()) names.clear();  // not one name per joint: by order
  return LoadBagImages(bag, options, robot.num_joints(), names);
}

}  // namespace selfcal::rosbag
