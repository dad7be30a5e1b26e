#include "capture/recorded_sequence.h"

#include <dirent.h>
#include <sys/stat.h>
#include <sys/types.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <set>
#include <sstream>


#include "base/atomic_file.h"
#include "base/crc32.h"
#include "capture/png_codec.h"
#include "yaml/yaml_reader.h"

namespace selfcal::capture {

namespace {

using yaml::YamlNode;

// The index's YAML rules: selfcal writes it with two levels of nesting (frames, entries) and one node per
// key and value, so a deeper or larger tree is damage.
constexpr int kMaxIndexDepth = 8;
constexpr std::size_t kMaxIndexNodes = 2000000;

std::string Join(const std::string& folder, const std::string& name) {
  if (folder.empty()) return name;
  return folder.back() == '/' ? folder + name : folder + "/" + name;
}

Status Corrupt(const std::string& message) { return CaptureFailure(CaptureError::kSequenceCorrupt, message); }

// A plain file name: no directory part, not hidden, printable ASCII.
bool SafeFileName(const std::string& name) {
  if (name.empty() || name.size() > 255 || name[0] == '.') return false;
  return std::all_of(name.begin(), name.end(), [](char c) { return c > 0x20 && c < 0x7F && c != '/' && c != '\\'; });
}

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string Quoted(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out.push_back('\\');
    out.push_back(c);
  }
  return out + "\"";
}

// ---- Index reading: every message is "<index>:<line>: <key>: <problem>".

class IndexReader {
 public:
  explicit IndexReader(std::string name) : name_(std::move(name)) {}

  Status Problem(const YamlNode& node, const std::string& key, const std::string& what) const {
    return Corrupt(name_ + ":" + std::to_string(node.line) + ": " + key + ": " + what);
  }

  Status Keys(const YamlNode& map, const std::string& where, const std::vector<std::string>& required,
              const std::vector<std::string>& optional) const {
    if (map.kind != YamlNode::Kind::kMap)
      return Problem(map, where, std::string("expected a map, found ") + map.KindName());
    std::string missing;
    for (const std::string& k : required) {
      if (map.Find(k) == nullptr) missing += (missing.empty() ? "`" : ", `") + k + "`";
    }
    if (!missing.empty()) return Problem(map, where, "missing key(s) " + missing);
    for (const std::string& k : map.keys) {
      const bool known =
          std::count(required.begin(), required.end(), k) + std::count(optional.begin(), optional.end(), k) > 0;
      if (!known) return Problem(map, where, "unknown key `" + k + "`");
    }
    return Status::Ok();
  }

  Status Integer(const YamlNode& map, const std::string& key, const std::string& where, int64_t min, int64_t max,
                 int64_t* out) const {
    const YamlNode& node = *map.Find(key);
    const std::string full = where.empty() ? key : where + "." + key;
    if (node.kind != YamlNode::Kind::kScalar || !node.plain) {
      return Problem(node, full, std::string("expected an integer, found ") + node.KindName());
    }
    errno = 0;
    char* end = nullptr;
    const long long v = std::strtoll(node.scalar.c_str(), &end, 10);
    if (node.scalar.empty() || *end != '\0' || errno == ERANGE) {
      return Problem(node, full, "expected an integer, found `" + node.scalar + "`");
    }
    if (v < min || v > max) {
      return Problem(node, full,
                     "value " + node.scalar + " outside [" + std::to_string(min) + ", " + std::to_string(max) + "]");
    }
    *out = v;
    return Status::Ok();
  }

  Status Real(const YamlNode& map, const std::string& key, const std::string& where, double* out) const {
    const YamlNode& node = *map.Find(key);
    const std::string full = where + "." + key;
    if (node.kind != YamlNode::Kind::kScalar || !node.plain) {
      return Problem(node, full, std::string("expected a number, found ") + node.KindName());
    }
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(node.scalar.c_str(), &end);
    if (node.scalar.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v)) {
      return Problem(node, full, "expected a finite number, found `" + node.scalar + "`");
    }
    *out = v;
    return Status::Ok();
  }

  Status String(const YamlNode& map, const std::string& key, const std::string& where, std::string* out) const {
    const YamlNode& node = *map.Find(key);
    const std::string full = where.empty() ? key : where + "." + key;
    if (node.kind != YamlNode::Kind::kScalar || node.scalar.empty()) {
      return Problem(node, full, std::string("expected a non-empty string, found ") + node.KindName());
    }
    *out = node.scalar;
    return Status::Ok();
  }

 private:
  std::string name_;
};

Status ParseIndex(const YamlNode& root, const std::string& name, const SequenceLimits& limits, SequenceIndex* index) {
  const IndexReader r(name);
  if (Status s = r.Keys(root, "index", {"format", "format_version", "camera", "frame_count", "frames"}, {}); !s.ok())
    return s;
  std::string format;
  if (Status s = r.String(root, "format", "", &format); !s.ok()) return s;
  if (format != kSequenceFormatName) {
    return r.Problem(*root.Find("format"), "format", "`" + format + "` is not " + kSequenceFormatName);
  }
  int64_t version = 0, width = 0, height = 0, count = 0;
  if (Status s = r.Integer(root, "format_version", "", 1, 1000000, &version); !s.ok()) return s;
  if (version != kSequenceFormatVersion) {
    return r.Problem(*root.Find("format_version"), "format_version",
                     "version " + std::to_string(version) + " is not the one this selfcal reads (" +
                         std::to_string(kSequenceFormatVersion) + ")");
  }
  const YamlNode& camera = *root.Find("camera");
  if (Status s = r.Keys(camera, "camera", {"width_px", "height_px"}, {}); !s.ok()) return s;
  if (Status s = r.Integer(camera, "width_px", "camera", 1, limits.max_width_px, &width); !s.ok()) return s;
  if (Status s = r.Integer(camera, "height_px", "camera", 1, limits.max_height_px, &height); !s.ok()) return s;
  if (Status s = r.Integer(root, "frame_count", "", 0, 1000000000, &count); !s.ok()) return s;
  index->format_version = static_cast<int>(version);
  index->width_px = static_cast<int>(width);
  index->height_px = static_cast<int>(height);

  const YamlNode& frames = *root.Find("frames");
  if (frames.kind == YamlNode::Kind::kNull) {
    // An empty block value: no frames yet.
  } else if (frames.kind != YamlNode::Kind::kSequence) {
    return r.Problem(frames, "frames", std::string("expected a sequence, found ") + frames.KindName());
  }
  if (static_cast<int64_t>(frames.items.size()) != count) {
    return r.Problem(*root.Find("frame_count"), "frame_count",
                     "says " + std::to_string(count) + " frames but the index lists " +
                         std::to_string(frames.items.size()) + " (index and images disagree)");
  }
  std::set<std::string> names;
  for (size_t i = 0; i < frames.items.size(); ++i) {
    const YamlNode& f = frames.items[i];
    const std::string where = "frames[" + std::to_string(i) + "]";
    if (Status s = r.Keys(f, where, {"pose_id", "image", "exposure_time_s", "sequence"}, {"size_bytes", "crc32"});
        !s.ok()) {
      return s;
    }
    SequenceEntry e;
    e.line = f.line;
    if (Status s = r.String(f, "pose_id", where, &e.pose_id); !s.ok()) return s;
    if (Status s = r.String(f, "image", where, &e.image); !s.ok()) return s;
    if (!SafeFileName(e.image) || !EndsWith(e.image, ".png")) {
      return r.Problem(*f.Find("image"), where + ".image",
                       "`" + e.image + "` is not a plain .png file name inside the folder");
    }
    if (!names.insert(e.image).second)
      return r.Problem(*f.Find("image"), where + ".image", "`" + e.image + "` is listed twice");
    if (Status s = r.Real(f, "exposure_time_s", where, &e.exposure_time_s); !s.ok()) return s;
    if (Status s = r.Integer(f, "sequence", where, 0, INT64_MAX, &e.sequence); !s.ok()) return s;
    if (f.Find("size_bytes") != nullptr) {
      if (Status s = r.Integer(f, "size_bytes", where, 0, static_cast<int64_t>(limits.max_image_bytes), &e.size_bytes);
          !s.ok()) {
        return s;
      }
    }
    if (const YamlNode* crc = f.Find("crc32"); crc != nullptr) {
      std::string hex;
      if (Status s = r.String(f, "crc32", where, &hex); !s.ok()) return s;
      const bool valid = hex.size() == 8 && std::all_of(hex.begin(), hex.end(), [](char c) {
                           return std::isxdigit(static_cast<unsigned char>(c));
                         });
      if (!valid) return r.Problem(*crc, where + ".crc32", "`" + hex + "` is not 8 hexadecimal digits");
      e.crc32 = static_cast<uint32_t>(std::strtoul(hex.c_str(), nullptr, 16));
    }
    if (!index->frames.empty()) {
      const SequenceEntry& p = index->frames.back();
      if (!(e.exposure_time_s > p.exposure_time_s)) {
        char text[160];
        std::snprintf(text, sizeof(text),
                      "%.9f s is not after the previous entry's %.9f s (line %d): timestamps out of order",
                      e.exposure_time_s, p.exposure_time_s, p.line);
        return r.Problem(*f.Find("exposure_time_s"), where + ".exposure_time_s", text);
      }
      if (!(e.sequence > p.sequence)) {
        return r.Problem(*f.Find("sequence"), where + ".sequence",
                         std::to_string(e.sequence) + " does not follow the previous entry's " +
                             std::to_string(p.sequence) + " (line " + std::to_string(p.line) + ")");
      }
    }
    index->frames.push_back(std::move(e));
  }
  return Status::Ok();
}

// PNG files in `folder` that `index` does not name.
Result<std::vector<std::string>> UnindexedImages(const std::string& folder, const SequenceIndex& index) {
  DIR* dir = ::opendir(folder.c_str());
  if (dir == nullptr) return Corrupt("cannot list " + folder + ": " + std::strerror(errno));
  std::set<std::string> named;
  for (const SequenceEntry& e : index.frames) named.insert(e.image);
  std::vector<std::string> extra;
  while (const dirent* d = ::readdir(dir)) {
    const std::string name = d->d_name;
    if (name[0] != '.' && EndsWith(name, ".png") && named.count(name) == 0) extra.push_back(name);
  }
  ::closedir(dir);
  std::sort(extra.begin(), extra.end());
  return extra;
}

// Width, height, bit depth and colour type from the PNG signature and IHDR chunk, before decoding.
Status CheckPngHeader(const std::string& bytes, const std::string& path, const SequenceIndex& index) {
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  if (bytes.size() < 33 || std::memcmp(bytes.data(), kSignature, 8) != 0 || bytes.compare(12, 4, "IHDR") != 0) {
    return Corrupt(path + " is not a PNG file (" + std::to_string(bytes.size()) + " bytes, no PNG signature and IHDR)");
  }
  auto be32 = [&](size_t at) {
    const auto* p = reinterpret_cast<const unsigned char*>(bytes.data() + at);
    return (uint32_t{p[0]} << 24) | (uint32_t{p[1]} << 16) | (uint32_t{p[2]} << 8) | uint32_t{p[3]};
  };
  const uint32_t width = be32(16), height = be32(20);
  const int depth = static_cast<unsigned char>(bytes[24]), colour = static_cast<unsigned char>(bytes[25]);
  if (width != static_cast<uint32_t>(index.width_px) || height != static_cast<uint32_t>(index.height_px)) {
    return Corrupt(path + " is " + std::to_string(width) + "x" + std::to_string(height) + " px; the sequence is " +
                   std::to_string(index.width_px) + "x" + std::to_string(index.height_px) +
                   " (resolution changed mid-sequence)");
  }
  if (depth != 8 || colour != 0) {
    return Corrupt(path + " has bit depth " + std::to_string(depth) + " and colour type " + std::to_string(colour) +
                   "; recorded frames are 8-bit grey PNG (depth 8, colour type 0)");
  }
  return Status::Ok();
}

}  // namespace

// ---- Index I/O

Result<SequenceIndex> ReadSequenceIndex(const std::string& folder, const SequenceLimits& limits) {
  const std::string path = Join(folder, kSequenceIndexName);
  bool missing = false;
  Result<std::string> text = ReadFileCapped(path, limits.max_index_bytes, &missing);
  if (!text.ok()) {
    return Corrupt(missing ? path + " does not exist: " + folder + " is not a recorded sequence"
                           : text.status().message());
  }
  yaml::YamlRules rules;
  rules.max_bytes = limits.max_index_bytes;
  rules.max_depth = kMaxIndexDepth;
  rules.max_nodes = kMaxIndexNodes;
  rules.wording = yaml::YamlWording::kSequenceIndex;
  Result<yaml::YamlDocument> doc = yaml::ParseYamlText(*text, path, rules);
  if (!doc.ok()) return Corrupt(doc.status().message());
  SequenceIndex index;
  if (Status s = ParseIndex(doc->root, path, limits, &index); !s.ok()) return s;
  return index;
}

std::string FormatSequenceIndex(const SequenceIndex& index) {
  std::ostringstream out;
  out << "# selfcal recorded sequence: images beside this file (see capture/recorded_sequence.h)\n";
  out << "format: " << kSequenceFormatName << "\n";
  out << "format_version: " << index.format_version << "\n";
  out << "camera:\n  width_px: " << index.width_px << "\n  height_px: " << index.height_px << "\n";
  out << "frame_count: " << index.frames.size() << "\n";
  out << "frames:" << (index.frames.empty() ? " []" : "") << "\n";
  for (const SequenceEntry& e : index.frames) {
    char time[64];
    std::snprintf(time, sizeof(time), "%.9f", e.exposure_time_s);
    out << "  - pose_id: " << Quoted(e.pose_id) << "\n";
    out << "    image: " << Quoted(e.image) << "\n";
    out << "    exposure_time_s: " << time << "\n";
    out << "    sequence: " << e.sequence << "\n";
    if (e.size_bytes >= 0) out << "    size_bytes: " << e.size_bytes << "\n";
    if (e.crc32) out << "    crc32: \"" << Crc32Hex(*e.crc32) << "\"\n";
  }
  return out.str();
}

// ---- Writer

Result<RecordedSequenceWriter> RecordedSequenceWriter::Create(const std::string& folder, int width_px, int height_px,
                                                              int png_compression) {
  if (width_px < 1 || height_px < 1) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot record " + folder + ": image size " + std::to_string(width_px) +
                                               "x" + std::to_string(height_px) + " must be positive");
  }
  if (png_compression < 0 || png_compression > 9) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "png_compression = " + std::to_string(png_compression) + " must lie in [0, 9]");
  }
  if (::mkdir(folder.c_str(), 0755) != 0) {
    const int error = errno;
    if (error != EEXIST)
      return Status::Error(ErrorCode::kInvalidInput, "cannot create " + folder + ": " + std::strerror(error));
    DIR* dir = ::opendir(folder.c_str());
    if (dir == nullptr) return Status::Error(ErrorCode::kInvalidInput, "cannot use " + folder + ": " + std::strerror(errno));
    bool empty = true;
    while (const dirent* d = ::readdir(dir)) {
      if (std::strcmp(d->d_name, ".") != 0 && std::strcmp(d->d_name, "..") != 0) empty = false;
    }
    ::closedir(dir);
    if (!empty) {
      return Status::Error(ErrorCode::kInvalidInput, "cannot record into " + folder +
                                                 ": the folder is not empty (a recording is never overwritten)");
    }
  }
  SequenceIndex index;
  index.width_px = width_px;
  index.height_px = height_px;
  if (Status s = WriteFileAtomically(Join(folder, kSequenceIndexName), FormatSequenceIndex(index),
                                               Publish::kReplace);
      !s.ok()) {
    return s;
  }
  return RecordedSequenceWriter(folder, std::move(index), png_compression);
}

Status RecordedSequenceWriter::Append(const Frame& frame, const std::string& pose_id) {
  const int w = static_cast<int>(frame.image.getWidth()), h = static_cast<int>(frame.image.getHeight());
  auto refuse = [&](const std::string& what) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "cannot append frame " + std::to_string(frame.sequence) + " to " + folder_ + ": " + what);
  };
  if (w != index_.width_px || h != index_.height_px) {
    return refuse("the image is " + std::to_string(w) + "x" + std::to_string(h) + ", the sequence " +
                  std::to_string(index_.width_px) + "x" + std::to_string(index_.height_px));
  }
  if (pose_id.empty() ||
      std::any_of(pose_id.begin(), pose_id.end(), [](char c) { return static_cast<unsigned char>(c) < 0x20; })) {
    return refuse("pose id `" + pose_id + "` must be non-empty without control characters");
  }
  if (!std::isfinite(frame.exposure_time_s)) return refuse("exposure time is not finite");
  if (frame.sequence < 0) return refuse("negative sequence number");
  if (!index_.frames.empty()) {
    const SequenceEntry& last = index_.frames.back();
    if (!(frame.exposure_time_s > last.exposure_time_s)) {
      return refuse("exposure time " + std::to_string(frame.exposure_time_s) + " s is not after the previous frame's " +
                    std::to_string(last.exposure_time_s) + " s");
    }
    if (frame.sequence <= last.sequence) {
      return refuse("sequence number does not advance past " + std::to_string(last.sequence));
    }
  }
  Result<std::string> png = EncodeGreyPng(frame.image, png_compression_);
  if (!png.ok()) return refuse(png.status().message());
  char name[32];
  std::snprintf(name, sizeof(name), "frame_%06zu.png", index_.frames.size());
  const std::string& bytes = *png;
  if (Status s = WriteFileAtomically(Join(folder_, name), bytes, Publish::kNoReplace); !s.ok())
    return s;
  SequenceIndex next = index_;
  SequenceEntry e;
  e.pose_id = pose_id;
  e.image = name;
  e.exposure_time_s = frame.exposure_time_s;
  e.sequence = frame.sequence;
  e.size_bytes = static_cast<int64_t>(bytes.size());
  e.crc32 = Crc32(bytes);
  next.frames.push_back(e);
  if (Status s = WriteFileAtomically(Join(folder_, kSequenceIndexName), FormatSequenceIndex(next),
                                               Publish::kReplace);
      !s.ok()) {
    return s;
  }
  index_ = std::move(next);
  return Status::Ok();
}

Status RecordedSequenceWriter::WriteAuxiliaryFile(const std::string& name, const std::string& contents) {
  if (!SafeFileName(name) || name == kSequenceIndexName) {
    return Status::Error(ErrorCode::kInvalidInput, "`" + name + "` is not a plain file name for " + folder_);
  }
  return WriteFileAtomically(Join(folder_, name), contents, Publish::kNoReplace);
}

// ---- Reader

RecordedSequence::RecordedSequence(std::string folder, RecordedSequenceOptions options)
    : folder_(std::move(folder)), options_(std::move(options)) {}

std::string RecordedSequence::Describe() const {
  std::ostringstream out;
  out << "recorded sequence " << folder_;
  if (!open_) return out.str() + " (not open)";
  out << ": " << index_.width_px << "x" << index_.height_px << " GREY8 (PNG), " << index_.frames.size()
      << " frames, next entry " << next_;
  return out.str();
}

Status RecordedSequence::Open() {
  Close();
  if (const std::string problems = options_.checks.Validate(); options_.check_frames && !problems.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "invalid frame check options for " + folder_ + ":\n" + problems);
  }
  Result<SequenceIndex> index = ReadSequenceIndex(folder_, options_.limits);
  if (!index.ok()) return index.status();
  if (!options_.allow_unindexed_images) {
    Result<std::vector<std::string>> extra = UnindexedImages(folder_, *index);
    if (!extra.ok()) return extra.status();
    if (!extra->empty()) {
      std::string list;
      for (size_t i = 0; i < extra->size() && i < 5; ++i) list += (i ? ", " : "") + (*extra)[i];
      if (extra->size() > 5) list += ", ...";
      return Corrupt(
          Join(folder_, kSequenceIndexName) + " lists " + std::to_string(index->frames.size()) +
          " images but the folder holds " + std::to_string(extra->size()) + " more PNG file(s) it does not name (" +
          list +
          "): index and images disagree (an interrupted recording leaves one; allow_unindexed_images accepts it)");
    }
  }
  index_ = std::move(*index);
  next_ = 0;
  open_ = true;
  return Status::Ok();
}

void RecordedSequence::Close() {
  open_ = false;
  index_ = SequenceIndex();
  next_ = 0;
}

Result<Frame> RecordedSequence::Load(const SequenceEntry& e) const {
  const std::string path = Join(folder_, e.image);
  const std::string at = " (entry at " + Join(folder_, kSequenceIndexName) + ":" + std::to_string(e.line) + ")";
  bool missing = false;
  Result<std::string> bytes = ReadFileCapped(path, options_.limits.max_image_bytes, &missing);
  if (!bytes.ok()) return Corrupt((missing ? "missing image " + path : bytes.status().message()) + at);
  if (e.size_bytes >= 0 && static_cast<int64_t>(bytes->size()) != e.size_bytes) {
    return Corrupt(path + " is " + std::to_string(bytes->size()) + " bytes; the index says " +
                   std::to_string(e.size_bytes) + " (truncated or replaced?)" + at);
  }
  if (e.crc32) {
    const uint32_t crc = Crc32(*bytes);
    if (crc != *e.crc32) {
      return Corrupt(path + " has CRC-32 " + Crc32Hex(crc) + "; the index says " +
                     Crc32Hex(*e.crc32) + " (checksum mismatch)" + at);
    }
  }
  if (Status s = CheckPngHeader(*bytes, path, index_); !s.ok()) return Corrupt(s.message() + at);
  Result<vpImage<unsigned char>> decoded = DecodeGreyPng(*bytes, path);
  if (!decoded.ok()) return Corrupt(decoded.status().message() + at);
  if (static_cast<int>(decoded->getWidth()) != index_.width_px ||
      static_cast<int>(decoded->getHeight()) != index_.height_px) {
    return Corrupt(path + " decodes to " + std::to_string(decoded->getWidth()) + "x" +
                   std::to_string(decoded->getHeight()) + "; expected " + std::to_string(index_.width_px) + "x" +
                   std::to_string(index_.height_px) + " grey" + at);
  }
  Frame frame;
  frame.image = std::move(decoded).value();
  frame.exposure_time_s = e.exposure_time_s;
  frame.sequence = e.sequence;
  frame.source = path;
  frame.pose_id = e.pose_id;
  if (options_.check_frames) {
    if (Status s = CheckFrame(frame.image, options_.checks, path); !s.ok()) return s;
  }
  return frame;
}

Result<Frame> RecordedSequence::Grab(double not_before_s, double /*timeout_s*/) {
  if (!open_) return Status::Error(ErrorCode::kInvalidInput, "Grab on " + folder_ + " before Open");
  const int n = static_cast<int>(index_.frames.size());
  while (next_ < n && index_.frames[next_].exposure_time_s < not_before_s) ++next_;
  if (next_ >= n) {
    char text[96];
    std::snprintf(text, sizeof(text), "no frame exposed at or after %.9f s", not_before_s);
    return CaptureFailure(CaptureError::kSequenceEnd,
                          "end of recorded sequence " + folder_ + " (" + std::to_string(n) + " frames): " + text);
  }
  // Advance first: a broken entry is skipped by the next Grab.
  const SequenceEntry& entry = index_.frames[next_++];
  return Load(entry);
}

}  // namespace selfcal::capture
