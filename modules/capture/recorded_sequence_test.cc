#include "capture/recorded_sequence.h"

#include <filesystem>
#include <limits>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "capture/capture_test_util.h"

namespace selfcal::capture {
namespace {

using testing::Contains;
using testing::ReadFile;
using testing::SameImage;
using testing::TempDir;
using testing::TestImage;
using testing::WriteFile;

constexpr int kWidth = 64;
constexpr int kHeight = 48;
constexpr double kNoLimit = -std::numeric_limits<double>::infinity();

Frame MakeFrame(int i) {
  Frame f;
  f.image = TestImage(kWidth, kHeight, i, 100 + static_cast<uint64_t>(i));
  f.exposure_time_s = 10.0 + 0.25 * i;
  f.sequence = 3 * i + 1;  // gaps are allowed
  return f;
}

std::string PoseId(int i) { return "p0" + std::to_string(i); }

// Records `n` frames into `<dir>/seq` and returns that folder.
std::string Record(const TempDir& dir, int n) {
  const std::string folder = dir.File("seq");
  Result<RecordedSequenceWriter> writer = RecordedSequenceWriter::Create(folder, kWidth, kHeight);
  EXPECT_TRUE(writer.ok()) << writer.status().ToString();
  if (!writer.ok()) return folder;
  for (int i = 0; i < n; ++i) {
    const Status s = writer.value().Append(MakeFrame(i), PoseId(i));
    EXPECT_TRUE(s.ok()) << s.ToString();
  }
  return folder;
}

std::string PngBytes(const cv::Mat& image) {
  std::vector<unsigned char> png;
  EXPECT_TRUE(cv::imencode(".png", image, png));
  return std::string(png.begin(), png.end());
}

// Rewrites the index after `edit`, e.g. to drop checksums so that the decoder itself meets the damage.
template <typename Edit>
void EditIndex(const std::string& folder, Edit edit) {
  Result<SequenceIndex> index = ReadSequenceIndex(folder);
  ASSERT_TRUE(index.ok()) << index.status().ToString();
  edit(&index.value());
  WriteFile(folder + "/index.yaml", FormatSequenceIndex(*index));
}

void ReplaceInFile(const std::string& path, const std::string& from, const std::string& to) {
  std::string text = ReadFile(path);
  const size_t at = text.find(from);
  ASSERT_NE(at, std::string::npos) << from;
  text.replace(at, from.size(), to);
  WriteFile(path, text);
}

// Opens `folder`, grabs everything, and returns the Status of the grab of entry `bad` (every other
// entry must load).
Status GrabAllExpectingOneBad(const std::string& folder, int n, int bad) {
  RecordedSequence sequence(folder);
  const Status open = sequence.Open();
  EXPECT_TRUE(open.ok()) << open.ToString();
  Status bad_status;
  for (int i = 0; i < n; ++i) {
    Result<Frame> f = sequence.Grab(kNoLimit, 0.0);
    if (i == bad) {
      EXPECT_FALSE(f.ok()) << "entry " << i;
      if (!f.ok()) bad_status = f.status();
    } else {
      EXPECT_TRUE(f.ok()) << "entry " << i << ": " << f.status().ToString();
      if (f.ok()) {
        EXPECT_TRUE(SameImage(f->image, MakeFrame(i).image)) << "entry " << i;
      }
    }
  }
  EXPECT_EQ(CaptureErrorOf(sequence.Grab(kNoLimit, 0.0).status()), CaptureError::kSequenceEnd);
  return bad_status;
}

TEST(RecordedSequence, RoundTripReplaysEveryFrameThenEnds) {
  TempDir dir;
  const std::string folder = Record(dir, 4);
  // Only the index and the images: no temporary file is left behind.
  EXPECT_EQ(dir.List("seq"), (std::vector<std::string>{"frame_000000.png", "frame_000001.png", "frame_000002.png",
                                                       "frame_000003.png", "index.yaml"}));
  RecordedSequence sequence(folder);
  EXPECT_TRUE(Contains(sequence.Describe(), "not open"));
  ASSERT_TRUE(sequence.Open().ok());
  EXPECT_TRUE(Contains(sequence.Describe(), "64x48")) << sequence.Describe();
  EXPECT_EQ(sequence.index().frames.size(), 4u);
  for (int i = 0; i < 4; ++i) {
    Result<Frame> f = sequence.Grab(kNoLimit, 0.0);
    ASSERT_TRUE(f.ok()) << f.status().ToString();
    const Frame expected = MakeFrame(i);
    EXPECT_TRUE(SameImage(f->image, expected.image)) << "frame " << i;  // PNG is lossless
    EXPECT_EQ(f->exposure_time_s, expected.exposure_time_s);            // 9 decimals: exact for these values
    EXPECT_EQ(f->sequence, expected.sequence);
    EXPECT_EQ(f->pose_id, PoseId(i));
    EXPECT_EQ(f->source, folder + "/frame_00000" + std::to_string(i) + ".png");
  }
  const Result<Frame> end = sequence.Grab(kNoLimit, 0.0);
  EXPECT_EQ(CaptureErrorOf(end.status()), CaptureError::kSequenceEnd);
  EXPECT_TRUE(Contains(end.status().message(), folder));
  // Reopening starts again.
  ASSERT_TRUE(sequence.Open().ok());
  EXPECT_EQ(sequence.Grab(kNoLimit, 0.0)->sequence, 1);
}

TEST(RecordedSequence, EmptySequenceEndsAtOnce) {
  TempDir dir;
  const std::string folder = Record(dir, 0);
  RecordedSequence sequence(folder);
  ASSERT_TRUE(sequence.Open().ok());
  EXPECT_EQ(sequence.index().width_px, kWidth);
  EXPECT_EQ(CaptureErrorOf(sequence.Grab(kNoLimit, 0.0).status()), CaptureError::kSequenceEnd);
}

TEST(RecordedSequence, GrabSkipsFramesExposedBeforeNotBefore) {
  TempDir dir;
  const std::string folder = Record(dir, 4);  // exposures 10.0, 10.25, 10.5, 10.75
  RecordedSequence sequence(folder);
  ASSERT_TRUE(sequence.Open().ok());
  Result<Frame> f = sequence.Grab(10.3, 1.0);
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(f->exposure_time_s, 10.5);  // 10.0 and 10.25 were stale for a settle time of 10.3 (V5)
  f = sequence.Grab(10.75, 1.0);        // at the settle time exactly: accepted
  ASSERT_TRUE(f.ok());
  EXPECT_EQ(f->exposure_time_s, 10.75);
  EXPECT_EQ(CaptureErrorOf(sequence.Grab(11.0, 1.0).status()), CaptureError::kSequenceEnd);
}

TEST(RecordedSequence, WriterRefusesWhatWouldCorruptARecording) {
  TempDir dir;
  const std::string folder = Record(dir, 2);
  // A second recording into the same folder.
  const Result<RecordedSequenceWriter> again = RecordedSequenceWriter::Create(folder, kWidth, kHeight);
  EXPECT_FALSE(again.ok());
  EXPECT_TRUE(Contains(again.status().message(), "not empty")) << again.status().message();

  Result<RecordedSequenceWriter> writer = RecordedSequenceWriter::Create(dir.File("other"), kWidth, kHeight);
  ASSERT_TRUE(writer.ok());
  ASSERT_TRUE(writer.value().Append(MakeFrame(1), "p1").ok());
  Frame wrong_size = MakeFrame(2);
  wrong_size.image = TestImage(32, 24, 0, 1);
  EXPECT_TRUE(Contains(writer.value().Append(wrong_size, "p2").message(), "32x24"));
  Frame earlier = MakeFrame(0);  // exposure 10.0 after 10.25
  EXPECT_TRUE(Contains(writer.value().Append(earlier, "p0").message(), "not after"));
  Frame same_sequence = MakeFrame(2);
  same_sequence.sequence = MakeFrame(1).sequence;
  EXPECT_TRUE(Contains(writer.value().Append(same_sequence, "p2").message(), "sequence number"));
  EXPECT_FALSE(writer.value().Append(MakeFrame(2), "").ok());
  EXPECT_EQ(writer->index().frames.size(), 1u);  // nothing of the refused frames reached the index

  ASSERT_TRUE(writer.value().WriteAuxiliaryFile("truth.yaml", "a: 1\n").ok());
  const Status twice = writer.value().WriteAuxiliaryFile("truth.yaml", "a: 2\n");
  EXPECT_TRUE(Contains(twice.message(), "never overwritten")) << twice.message();
  EXPECT_EQ(ReadFile(dir.File("other/truth.yaml")), "a: 1\n");
  EXPECT_FALSE(writer.value().WriteAuxiliaryFile("../escape.yaml", "x").ok());
  EXPECT_FALSE(writer.value().WriteAuxiliaryFile("index.yaml", "x").ok());
}

// ---- V8: each corruption gives kSequenceCorrupt naming the file; entries after it still replay.

TEST(RecordedSequenceV8, MissingImage) {
  TempDir dir;
  const std::string folder = Record(dir, 3);
  std::filesystem::remove(folder + "/frame_000001.png");
  const Status s = GrabAllExpectingOneBad(folder, 3, 1);
  EXPECT_EQ(CaptureErrorOf(s), CaptureError::kSequenceCorrupt);
  EXPECT_TRUE(Contains(s.message(), "missing image " + folder + "/frame_000001.png")) << s.message();
  EXPECT_TRUE(Contains(s.message(), "(entry at " + folder + "/index.yaml:")) << s.message();
}

TEST(RecordedSequenceV8, TruncatedImageCaughtBySizeAndByTheDecoder) {
  TempDir dir;
  const std::string folder = Record(dir, 3);
  const std::string path = folder + "/frame_000002.png";
  const std::string bytes = ReadFile(path);
  WriteFile(path, bytes.substr(0, bytes.size() / 2));
  Status s = GrabAllExpectingOneBad(folder, 3, 2);
  EXPECT_EQ(CaptureErrorOf(s), CaptureError::kSequenceCorrupt);
  EXPECT_TRUE(Contains(s.message(), path)) << s.message();
  EXPECT_TRUE(Contains(s.message(), "the index says")) << s.message();
  // Without size and checksum in the index, the PNG decoder meets the truncation.
  EditIndex(folder, [](SequenceIndex* index) {
    index->frames[2].size_bytes = -1;
    index->frames[2].crc32.reset();
  });
  s = GrabAllExpectingOneBad(folder, 3, 2);
  EXPECT_EQ(CaptureErrorOf(s), CaptureError::kSequenceCorrupt);
  EXPECT_TRUE(Contains(s.message(), "cannot decode " + path)) << s.message();
}

TEST(RecordedSequenceV8, UnreadableImage) {
  TempDir dir;
  const std::string folder = Record(dir, 3);
  WriteFile(folder + "/frame_000000.png", "this is not an image at all, just text");
  EditIndex(folder, [](SequenceIndex* index) {
    index->frames[0].size_bytes = -1;
    index->frames[0].crc32.reset();
  });
  const Status s = GrabAllExpectingOneBad(folder, 3, 0);
  EXPECT_EQ(CaptureErrorOf(s), CaptureError::kSequenceCorrupt);
  EXPECT_TRUE(Contains(s.message(), folder + "/frame_000000.png is not a PNG file")) << s.message();
}

TEST(RecordedSequenceV8, ResolutionChangeMidSequence) {
  TempDir dir;
  const std::string folder = Record(dir, 3);
  const cv::Mat small(24, 32, CV_8UC1, cv::Scalar(120));
  WriteFile(folder + "/frame_000001.png", PngBytes(small));
  EditIndex(folder, [](SequenceIndex* index) {
    index->frames[1].size_bytes = -1;
    index->frames[1].crc32.reset();
  });
  const Status s = GrabAllExpectingOneBad(folder, 3, 1);
  EXPECT_EQ(CaptureErrorOf(s), CaptureError::kSequenceCorrupt);
  EXPECT_TRUE(Contains(s.message(), folder + "/frame_000001.png is 32x24 px; the sequence is 64x48")) << s.message();
}

TEST(RecordedSequenceV8, ColourImageRefused) {
  TempDir dir;
  const std::string folder = Record(dir, 2);
  const cv::Mat colour(kHeight, kWidth, CV_8UC3, cv::Scalar(120, 20, 200));
  WriteFile(folder + "/frame_000001.png", PngBytes(colour));
  EditIndex(folder, [](SequenceIndex* index) {
    index->frames[1].size_bytes = -1;
    index->frames[1].crc32.reset();
  });
  const Status s = GrabAllExpectingOneBad(folder, 2, 1);
  EXPECT_TRUE(Contains(s.message(), "colour type 2")) << s.message();
}

TEST(RecordedSequenceV8, ChecksumMismatch) {
  TempDir dir;
  const std::string folder = Record(dir, 3);
  const std::string path = folder + "/frame_000001.png";
  std::string bytes = ReadFile(path);
  bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x5A);  // same size, other content
  WriteFile(path, bytes);
  const Status s = GrabAllExpectingOneBad(folder, 3, 1);
  EXPECT_EQ(CaptureErrorOf(s), CaptureError::kSequenceCorrupt);
  EXPECT_TRUE(Contains(s.message(), path + " has CRC-32")) << s.message();
  EXPECT_TRUE(Contains(s.message(), "checksum mismatch")) << s.message();
}

TEST(RecordedSequenceV8, TimestampsOutOfOrderRefuseTheSequence) {
  TempDir dir;
  const std::string folder = Record(dir, 3);
  ReplaceInFile(folder + "/index.yaml", "exposure_time_s: 10.500000000", "exposure_time_s: 10.100000000");
  RecordedSequence sequence(folder);
  const Status s = sequence.Open();
  EXPECT_EQ(CaptureErrorOf(s), CaptureError::kSequenceCorrupt);
  EXPECT_TRUE(Contains(s.message(), folder + "/index.yaml:")) << s.message();
  EXPECT_TRUE(Contains(s.message(), "frames[2].exposure_time_s")) << s.message();
  EXPECT_TRUE(Contains(s.message(), "out of order")) << s.message();
  EXPECT_FALSE(sequence.Grab(kNoLimit, 0).ok());  // not open
}

TEST(RecordedSequenceV8, IndexAndImageCountsDisagree) {
  TempDir dir;
  const std::string folder = Record(dir, 3);
  // frame_count says 4, three entries.
  ReplaceInFile(folder + "/index.yaml", "frame_count: 3", "frame_count: 4");
  RecordedSequence sequence(folder);
  Status s = sequence.Open();
  EXPECT_EQ(CaptureErrorOf(s), CaptureError::kSequenceCorrupt);
  EXPECT_TRUE(Contains(s.message(), "frame_count: says 4 frames but the index lists 3")) << s.message();
  ReplaceInFile(folder + "/index.yaml", "frame_count: 4", "frame_count: 3");
  // An image the index does not name (what an interrupted recording leaves).
  WriteFile(folder + "/frame_000003.png", ReadFile(folder + "/frame_000000.png"));
  s = sequence.Open();
  EXPECT_EQ(CaptureErrorOf(s), CaptureError::kSequenceCorrupt);
  EXPECT_TRUE(Contains(s.message(), "frame_000003.png")) << s.message();
  EXPECT_TRUE(Contains(s.message(), "index and images disagree")) << s.message();
  RecordedSequenceOptions lenient;
  lenient.allow_unindexed_images = true;
  RecordedSequence tolerant(folder, lenient);
  EXPECT_TRUE(tolerant.Open().ok());
  EXPECT_EQ(tolerant.index().frames.size(), 3u);
}

TEST(RecordedSequenceV8, MalformedIndexNamesFileLineAndKey) {
  TempDir dir;
  const std::string folder = Record(dir, 2);
  const std::string index = folder + "/index.yaml";
  const std::string good = ReadFile(index);
  struct Case {
    std::string from, to, expected;
  };
  const std::vector<Case> cases = {
      {"sequence: 1\n", "sequence: 1\n    sequense: 2\n", "unknown key `sequense`"},
      {"    sequence: 1\n", "", "missing key(s) `sequence`"},
      {"exposure_time_s: 10.000000000", "exposure_time_s: .nan", "expected a finite number, found `.nan`"},
      {"exposure_time_s: 10.000000000", "exposure_time_s: ten", "expected a finite number, found `ten`"},
      {"\"frame_000000.png\"", "\"../frame_000000.png\"", "not a plain .png file name"},
      {"\"frame_000001.png\"", "\"frame_000000.png\"", "listed twice"},
      {"width_px: 64", "width_px: 0", "camera.width_px: value 0 outside"},
      {"format_version: 1", "format_version: 2", "version 2 is not the one"},
      {"pose_id: \"p00\"", "pose_id: &a \"p00\"", "anchors are not allowed"},
      {"frames:\n", "frames: [[[[[[[[[[]]]]]]]]]]\nx:\n", "nested deeper"},
      {"camera:\n", "camera: {\n", "malformed YAML"},
  };
  for (const Case& c : cases) {
    WriteFile(index, good);
    ReplaceInFile(index, c.from, c.to);
    RecordedSequence sequence(folder);
    const Status s = sequence.Open();
    EXPECT_EQ(CaptureErrorOf(s), CaptureError::kSequenceCorrupt) << c.expected;
    EXPECT_TRUE(Contains(s.message(), index)) << s.message();
    EXPECT_TRUE(Contains(s.message(), c.expected)) << "expected `" << c.expected << "` in: " << s.message();
  }
  WriteFile(index, std::string("\x89PNG\r\n\x1a\n\x00\x00", 10));
  EXPECT_TRUE(Contains(RecordedSequence(folder).Open().message(), "invalid byte"));
  std::filesystem::remove(index);
  const Status missing = RecordedSequence(folder).Open();
  EXPECT_EQ(CaptureErrorOf(missing), CaptureError::kSequenceCorrupt);
  EXPECT_TRUE(Contains(missing.message(), "is not a recorded sequence")) << missing.message();
}

TEST(RecordedSequence, BadFramesAreReportedAsBadFrames) {
  TempDir dir;
  const std::string folder = dir.File("seq");
  Result<RecordedSequenceWriter> writer = RecordedSequenceWriter::Create(folder, kWidth, kHeight);
  ASSERT_TRUE(writer.ok());
  Frame black = MakeFrame(0);
  black.image = testing::Uniform(kWidth, kHeight, 0);
  ASSERT_TRUE(writer.value().Append(black, "p0").ok());
  ASSERT_TRUE(writer.value().Append(MakeFrame(1), "p1").ok());
  RecordedSequence sequence(folder);
  ASSERT_TRUE(sequence.Open().ok());
  const Result<Frame> first = sequence.Grab(kNoLimit, 0);
  EXPECT_EQ(CaptureErrorOf(first.status()), CaptureError::kBadFrame);
  EXPECT_TRUE(Contains(first.status().message(), folder + "/frame_000000.png")) << first.status().message();
  EXPECT_TRUE(sequence.Grab(kNoLimit, 0).ok());
}

}  // namespace
}  // namespace selfcal::capture
