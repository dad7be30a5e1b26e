// Recorded sequences (../shared/RELIABILITY.md V8): a folder that replays like a camera.
//
//   <folder>/index.yaml          the manifest, rewritten atomically after every image
//   <folder>/frame_000000.png    8-bit grey PNG, one per frame, written atomically before the index
//   <folder>/...                 auxiliary files (e.g. truth.yaml of a rendered sequence)
//
// index.yaml (format_version 1; every key required unless marked optional, unknown keys refused):
//
//   format: selfcal-recorded-sequence
//   format_version: 1
//   camera: {width_px: 640, height_px: 480}
//   frame_count: 2                      # must equal the number of entries below
//   frames:
//     - pose_id: "p00"                  # the pose the frame belongs to (non-empty string)
//       image: "frame_000000.png"       # file in the folder: no '/', not hidden, ends in .png
//       exposure_time_s: 12.500000000   # source clock (CLOCK_MONOTONIC for live cameras); strictly increasing
//       sequence: 0                     # strictly increasing (gaps = frames the recorder skipped)
//       size_bytes: 10452               # optional: the image file's size
//       crc32: "1c291ca3"               # optional: CRC-32 (IEEE, as zlib) of the image file's bytes
//
// Validation. Open() reads the index (size-capped, strict YAML) and refuses, with kSequenceCorrupt
// naming index.yaml and the line, anything that makes the sequence as a whole untrustworthy: malformed
// YAML, missing or unknown keys, wrong types, non-finite or out-of-range numbers, frame_count different
// from the entries, duplicate image names, unsafe names, timestamps or sequence numbers not strictly
// increasing, and (unless allow_unindexed_images) PNG files in the folder the index does not name — the
// signature of a recording interrupted between writing an image and its index entry. Each entry's
// image is checked when grabbed: missing file, size or CRC mismatch, not a PNG, wrong bit depth or
// colour type, another resolution than the camera's, undecodable (truncated) data. Such an entry gives
// kSequenceCorrupt naming the image file, and the next Grab continues with the following entry (a
// skipped sample with a reason). Frames that decode but fail the sanity checks give kBadFrame. The PNG
// header is read and its size checked against the limits before anything is decoded.
//
// Grab(not_before_s, timeout_s) returns the next entry whose exposure_time_s >= not_before_s, skipping
// earlier ones (as a live camera drops stale frames); kSequenceEnd when none is left. It never waits:
// timeout_s is irrelevant. Replaying a recorded session passes the recorded settle times.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "base/status.h"
#include "capture/frame_checks.h"
#include "capture/frame_source.h"

namespace selfcal::capture {

inline constexpr int kSequenceFormatVersion = 1;
inline constexpr const char* kSequenceFormatName = "selfcal-recorded-sequence";
inline constexpr const char* kSequenceIndexName = "index.yaml";

struct SequenceLimits {
  std::size_t max_index_bytes = 16u << 20;  // 16 MiB: about 100 000 entries
  std::size_t max_image_bytes = 64u << 20;  // per PNG file
  int max_width_px = 16384;
  int max_height_px = 16384;
};

struct SequenceEntry {
  std::string pose_id;
  std::string image;  // file name inside the folder
  double exposure_time_s = 0;
  int64_t sequence = 0;
  int64_t size_bytes = -1;        // -1: not recorded
  std::optional<uint32_t> crc32;  // empty: not recorded
  int line = 0;                   // of the entry in index.yaml, for messages
};

struct SequenceIndex {
  int format_version = kSequenceFormatVersion;
  int width_px = 0;
  int height_px = 0;
  std::vector<SequenceEntry> frames;
};

// Reads and validates `<folder>/index.yaml` as Open() does (no image is read). kSequenceCorrupt naming
// the file and line.
Result<SequenceIndex> ReadSequenceIndex(const std::string& folder, const SequenceLimits& limits = SequenceLimits());

// The index as text (what the writer writes). Strings are double-quoted; times have 9 decimals.
std::string FormatSequenceIndex(const SequenceIndex& index);

// Writes a sequence folder frame by frame. Every image is written atomically (temporary file, fsync,
// link: an existing file is never replaced) before the index entry naming it, and the whole index is
// then rewritten atomically (temporary file + rename), so after a crash the folder holds a valid
// sequence of every frame appended before it, plus possibly one image not yet indexed. Rewriting the
// index costs O(frames) per Append: fine for the few hundred frames of a session.
class RecordedSequenceWriter {
 public:
  // Creates `folder` (its parent must exist), or uses it if it is an empty directory; refuses a folder
  // with anything in it (a recording is never overwritten). Writes an index with no frames.
  // ErrorCode::kInvalidInput naming the folder.
  static Result<RecordedSequenceWriter> Create(const std::string& folder, int width_px, int height_px,
                                               int png_compression = 6);

  // Appends `frame` (its image must be width x height; exposure time and sequence number must increase
  // strictly) as the next entry, with the image's size and CRC-32. ErrorCode::kInvalidInput naming the file or
  // the offending value; on failure the index still describes the frames appended before.
  Status Append(const Frame& frame, const std::string& pose_id);

  // Writes `<folder>/<name>` atomically, refusing to replace an existing file (a truth file, a journal
  // extract). `name` must be a plain file name other than index.yaml.
  Status WriteAuxiliaryFile(const std::string& name, const std::string& contents);

  const std::string& folder() const { return folder_; }
  const SequenceIndex& index() const { return index_; }

 private:
  RecordedSequenceWriter(std::string folder, SequenceIndex index, int png_compression)
      : folder_(std::move(folder)), index_(std::move(index)), png_compression_(png_compression) {}
  std::string folder_;
  SequenceIndex index_;
  int png_compression_ = 6;
};

struct RecordedSequenceOptions {
  SequenceLimits limits;
  bool check_frames = true;  // run CheckFrame on every decoded image (kBadFrame)
  FrameCheckOptions checks;
  // Accept PNG files in the folder that the index does not name (e.g. the last image of an interrupted
  // recording); they are ignored.
  bool allow_unindexed_images = false;
};

class RecordedSequence : public FrameSource {
 public:
  explicit RecordedSequence(std::string folder, RecordedSequenceOptions options = RecordedSequenceOptions());

  std::string Describe() const override;
  Status Open() override;
  Result<Frame> Grab(double not_before_s, double timeout_s) override;
  void Close() override;

  // After Open: the validated index, and the entry the next Grab starts from.
  const SequenceIndex& index() const { return index_; }
  int next_entry() const { return next_; }

 private:
  Result<Frame> Load(const SequenceEntry& entry) const;

  std::string folder_;
  RecordedSequenceOptions options_;
  SequenceIndex index_;
  bool open_ = false;
  int next_ = 0;
};

}  // namespace selfcal::capture
