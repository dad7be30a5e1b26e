// MJPEG decoding on recorded frames (test/data/mjpeg, made from the rendered dot images of
// test/data/sequences by its make_frames.py), and damaged frames refused: no camera needed.
#include "capture/mjpeg_decode.h"

#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "capture/capture_test_util.h"
#include "capture/frame_source.h"
#include "capture/png_codec.h"

namespace selfcal::capture {
namespace {

using testing::Contains;
using testing::ReadFile;

const std::string kData = std::string(SELFCAL_SOURCE_DIR) + "/test/data/";

std::string Frame(const std::string& name) { return ReadFile(kData + "mjpeg/" + name); }

Result<vpImage<unsigned char>> Decode(const std::string& bytes, int width = 0, int height = 0) {
  return DecodeMjpegFrame(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), "/dev/video7 frame 3", width,
                          height);
}

struct Difference {
  double mean = 0;
  int max = 0;
};

Difference Compare(const vpImage<unsigned char>& a, const vpImage<unsigned char>& b) {
  Difference d;
  for (unsigned i = 0; i < a.getSize(); ++i) {
    const int e = std::abs(static_cast<int>(a.bitmap[i]) - static_cast<int>(b.bitmap[i]));
    d.mean += e;
    d.max = std::max(d.max, e);
  }
  d.mean /= a.getSize();
  return d;
}

TEST(MjpegDecode, RecordedFramesDecodeToTheirSourceImage) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"puma_clean_640x480", "sequences/puma_arc_clean/frame_000000.png"},
      {"puma_noisy_640x480", "sequences/puma_arc_noisy/frame_000001.png"}};
  for (const auto& [name, png] : cases) {
    Result<vpImage<unsigned char>> source = DecodeGreyPng(ReadFile(kData + png), png);
    ASSERT_TRUE(source.ok()) << source.status().message();
    Result<vpImage<unsigned char>> decoded = Decode(Frame(name + ".jpg"), 640, 480);
    ASSERT_TRUE(decoded.ok()) << decoded.status().message();
    ASSERT_EQ(decoded->getWidth(), 640u);
    ASSERT_EQ(decoded->getHeight(), 480u);
    // Quality 85, 4:2:2: the luminance within a few grey levels (the dots' edges carry the largest error).
    const Difference d = Compare(*decoded, *source);
    EXPECT_LT(d.mean, 1.5) << name;
    EXPECT_LT(d.max, 48) << name;
    EXPECT_GT(d.max, 0) << name << ": a lossy frame identical to its source: the test reads the wrong file";
  }
}

TEST(MjpegDecode, FramesWithoutHuffmanTablesAsUvcCamerasSendThem) {
  const std::string full = Frame("puma_clean_640x480.jpg"), bare = Frame("puma_clean_640x480_nodht.jpg");
  ASSERT_NE(full.find("\xFF\xC4"), std::string::npos) << "the full frame has its Huffman tables";
  EXPECT_EQ(bare.find("\xFF\xC4"), std::string::npos) << "the fixture still has a DHT segment";
  Result<vpImage<unsigned char>> a = Decode(full), b = Decode(bare);
  ASSERT_TRUE(a.ok()) << a.status().message();
  ASSERT_TRUE(b.ok()) << b.status().message();
  EXPECT_TRUE(testing::SameImage(*a, *b));
}

void ExpectRefused(const std::string& bytes, const std::string& what, CaptureError error = CaptureError::kBadFrame,
                   int width = 640, int height = 480) {
  Result<vpImage<unsigned char>> decoded = Decode(bytes, width, height);
  ASSERT_FALSE(decoded.ok()) << what << " was decoded";
  EXPECT_EQ(CaptureErrorOf(decoded.status()), error) << what << ": " << decoded.status().message();
  EXPECT_TRUE(Contains(decoded.status().message(), "/dev/video7 frame 3")) << decoded.status().message();
}

TEST(MjpegDecode, TruncatedFramesAreRefused) {
  const std::string full = Frame("puma_noisy_640x480_nodht.jpg");
  for (double fraction : {0.1, 0.5, 0.9, 0.99}) {
    const std::string cut = full.substr(0, static_cast<size_t>(fraction * full.size()));
    ExpectRefused(cut, "a frame cut at " + std::to_string(fraction));
    Result<vpImage<unsigned char>> decoded = Decode(cut);
    EXPECT_TRUE(Contains(decoded.status().message(), "corrupt or truncated")) << decoded.status().message();
  }
  ExpectRefused(full.substr(0, full.size() - 2), "a frame without its end-of-image marker");
  // A frame the USB transfer padded with zeros after its end is whole.
  EXPECT_TRUE(Decode(full + std::string(64, '\0'), 640, 480).ok());
}

TEST(MjpegDecode, CorruptFramesAreRefused) {
  const std::string full = Frame("puma_clean_640x480.jpg");
  const size_t scan = full.find("\xFF\xDA");
  ASSERT_NE(scan, std::string::npos);
  std::string marker = full;  // a stray restart marker in the entropy-coded data
  marker[scan + 4000] = '\xFF';
  marker[scan + 4001] = '\xD3';
  ExpectRefused(marker, "a frame with a stray marker");
  std::string zeros = full;  // a lost USB packet's worth of zeros
  for (size_t i = scan + 3000; i < scan + 3000 + 1024; ++i) zeros[i] = '\0';
  ExpectRefused(zeros, "a frame with a zeroed block");
  std::string header = full;  // the frame header's height broken
  const size_t sof = full.find("\xFF\xC0");
  ASSERT_NE(sof, std::string::npos);
  header[sof + 5] = '\0';
  header[sof + 6] = '\0';
  ExpectRefused(header, "a frame with a zero height");
}

TEST(MjpegDecode, WhatIsNotAJpegIsRefused) {
  ExpectRefused("", "an empty buffer");
  ExpectRefused(std::string(4096, '\0'), "a buffer of zeros");
  ExpectRefused(ReadFile(kData + "sequences/puma_arc_clean/frame_000000.png"), "a PNG");
  Result<vpImage<unsigned char>> png = Decode(ReadFile(kData + "sequences/puma_arc_clean/frame_000000.png"));
  EXPECT_TRUE(Contains(png.status().message(), "start-of-image")) << png.status().message();
}

TEST(MjpegDecode, AFrameOfAnotherSizeThanNegotiatedIsAFormatMismatch) {
  ExpectRefused(Frame("puma_clean_640x480.jpg"), "a 640x480 frame on a 1280x720 stream",
                CaptureError::kFormatMismatch, 1280, 720);
  Result<vpImage<unsigned char>> decoded = Decode(Frame("puma_clean_640x480.jpg"), 1280, 720);
  EXPECT_TRUE(Contains(decoded.status().message(), "is 640x480, not the 1280x720 negotiated")) << decoded.status().message();
}

}  // namespace
}  // namespace selfcal::capture
