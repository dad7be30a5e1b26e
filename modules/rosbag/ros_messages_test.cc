// The ROS 2 messages from CDR (test_bytes.h writes them field by field with the alignment rules): values
// read back, every truncation refused naming the field, other encapsulations and encodings refused; the
// images made grey as ViSP makes colour grey, and a PNG CompressedImage decoded to the same pixels.
#include "rosbag/ros_messages.h"

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>
#include <visp3/core/vpImageConvert.h>

#include "rosbag/test_bytes.h"

namespace selfcal::rosbag {
namespace {

using testing::CdrWriter;

TEST(RosMessages, JointStateReadBackWithItsAlignment) {
  const std::string cdr = testing::JointStateCdr(12, 500000000, {"shoulder", "elbow"}, {0.25, -1.5});
  Result<JointStateMessage> m = DecodeJointState(cdr, "bag.mcap: byte 99");
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  EXPECT_DOUBLE_EQ(m->stamp.seconds(), 12.5);
  EXPECT_EQ(m->frame_id, "base");
  EXPECT_EQ(m->name, (std::vector<std::string>{"shoulder", "elbow"}));
  EXPECT_EQ(m->position, (std::vector<double>{0.25, -1.5}));
  EXPECT_TRUE(m->velocity.empty());
  // Names "a", "bc", "d" leave the doubles' count ending at offset 52 after the header: the first double
  // is aligned to 8, at 56 (the 4-byte alignment of XCDR2 would read it at 52).
  Result<JointStateMessage> padded =
      DecodeJointState(testing::JointStateCdr(0, 0, {"a", "bc", "d"}, {0.5, 2.0, -3.0}), "w");
  ASSERT_TRUE(padded.ok()) << padded.status().ToString();
  EXPECT_EQ(padded->position, (std::vector<double>{0.5, 2.0, -3.0}));
}

TEST(RosMessages, EveryTruncationAndAWrongEncapsulationAreRefused) {
  const std::string cdr = testing::JointStateCdr(1, 2, {"a", "b", "c"}, {1, 2, 3});
  for (size_t n = 0; n < cdr.size(); ++n) {
    Result<JointStateMessage> m = DecodeJointState(cdr.substr(0, n), "bag.mcap: byte 7");
    ASSERT_FALSE(m.ok()) << "cut at " << n;
    EXPECT_EQ(m.status().message().rfind("bag.mcap: byte 7 (sensor_msgs/msg/JointState): message field `", 0), 0u)
        << m.status().message();
  }
  std::string big = cdr;
  big[1] = 0;
  Result<JointStateMessage> m = DecodeJointState(big, "w");
  ASSERT_FALSE(m.ok());
  EXPECT_NE(m.status().message().find("encapsulation 00 00"), std::string::npos) << m.status().message();
  std::string huge = cdr;
  huge[4 + 8 + 4 + 5 + 3 + 3] = '\x7f';  // the name count's high byte (after stamp, frame_id "base\0", padding)
  EXPECT_FALSE(DecodeJointState(huge, "w").ok());
}

std::string ImageCdr(std::uint32_t height, std::uint32_t width, const std::string& encoding, std::uint32_t step,
                     const std::string& data) {
  CdrWriter w;
  w.Add<std::int32_t>(3).Add<std::uint32_t>(0).Str("camera").Add(height).Add(width).Str(encoding);
  w.Add<std::uint8_t>(0).Add(step).Octets(data);
  return w.bytes();
}

TEST(RosMessages, RawImagesMadeGreyAsViSPDoesWithTheirRowStep) {
  const std::string rgb("\x10\x20\x30\xff\x00\x00PP\x40\x50\x60\x00\x00\xff" "PP", 16);  // 2x2, step 8 (2 padding)
  Result<ImageMessage> m = DecodeImage(ImageCdr(2, 2, "rgb8", 8, rgb), "w");
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  Result<vpImage<unsigned char>> grey = GreyImage(*m, "w");
  ASSERT_TRUE(grey.ok()) << grey.status().ToString();
  unsigned char packed[12] = {0x10, 0x20, 0x30, 0xff, 0, 0, 0x40, 0x50, 0x60, 0, 0, 0xff}, expected[4];
  vpImageConvert::RGBToGrey(packed, expected, 4);
  for (int k = 0; k < 4; ++k) EXPECT_EQ(grey->bitmap[k], expected[k]) << k;

  Result<ImageMessage> depth = DecodeImage(ImageCdr(1, 1, "16UC1", 2, "ab"), "w");
  ASSERT_TRUE(depth.ok());
  Result<vpImage<unsigned char>> refused = GreyImage(*depth, "bag.mcap: byte 5");
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.status().message().find("image encoding `16UC1`"), std::string::npos);
  Result<ImageMessage> short_data = DecodeImage(ImageCdr(2, 2, "mono8", 2, "abc"), "w");
  ASSERT_TRUE(short_data.ok());
  EXPECT_FALSE(GreyImage(*short_data, "w").ok());
}

TEST(RosMessages, CompressedPngDecodedToTheSamePixels) {
  cv::Mat grey(3, 5, CV_8UC1);
  for (int k = 0; k < 15; ++k) grey.data[k] = static_cast<unsigned char>(17 * k);
  std::vector<unsigned char> png;
  ASSERT_TRUE(cv::imencode(".png", grey, png));
  CdrWriter w;
  w.Add<std::int32_t>(3).Add<std::uint32_t>(0).Str("camera").Str("png").Octets(std::string(png.begin(), png.end()));
  Result<ImageMessage> m = DecodeCompressedImage(w.bytes(), "w");
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  Result<vpImage<unsigned char>> out = GreyImage(*m, "w");
  ASSERT_TRUE(out.ok()) << out.status().ToString();
  ASSERT_EQ(out->getWidth(), 5u);
  for (int k = 0; k < 15; ++k) EXPECT_EQ(out->bitmap[k], grey.data[k]);
  ImageMessage broken = *m;
  broken.data = "not a png";
  EXPECT_FALSE(GreyImage(broken, "w").ok());
}

}  // namespace
}  // namespace selfcal::rosbag
