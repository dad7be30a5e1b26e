#include "sim/render_sequence.h"

#include <sys/stat.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "capture/recorded_sequence.h"
#include "sim/simulated_camera.h"

namespace selfcal::sim {

namespace {

constexpr const char* kTruthFormat = "selfcal-sequence-truth";
constexpr long long kMaxTruthBytes = 64ll << 20;

std::string Fixed(double v, int decimals) {
  char text[64];
  std::snprintf(text, sizeof(text), "%.*f", decimals, v);
  return text;
}

std::string Pair(const Eigen::Vector2d& p) { return "[" + Fixed(p.x(), 4) + ", " + Fixed(p.y(), 4) + "]"; }

std::string Quoted(const std::string& s) {
  std::string out = "\"";
  for (const char c : s) {
    if (c == '"' || c == '\\') out.push_back('\\');
    out.push_back(c);
  }
  return out + "\"";
}

std::string FormatTruth(const SequenceTruth& t) {
  std::ostringstream out;
  out << "# Truth of a rendered sequence (sim/render_sequence.h); images and index.yaml beside it.\n";
  out << "format: " << kTruthFormat << "\nformat_version: 1\n";
  out << "world: " << Quoted(t.world_description) << "\n";
  out << "camera: {width_px: " << t.camera.width_px << ", height_px: " << t.camera.height_px
      << ", fx_px: " << Fixed(t.camera.fx_px, 9) << ", mu: " << Fixed(t.camera.mu, 12)
      << ", cx_px: " << Fixed(t.camera.cx_px, 9) << ", cy_px: " << Fixed(t.camera.cy_px, 9)
      << ", k1: " << Fixed(t.camera.k1, 12) << "}\n";
  out << "dot_radius_m: " << Fixed(t.dot_radius_m, 9) << "\n";
  const RenderOptions& r = t.render;
  out << "render: {supersampling: " << r.supersampling << ", background_grey: " << Fixed(r.background_grey, 6)
      << ", dot_grey: " << Fixed(r.dot_grey, 6) << ", blur_sigma_px: " << Fixed(r.blur_sigma_px, 6)
      << ", noise_std_grey: " << Fixed(r.noise_std_grey, 6) << ", noise_seed: " << r.noise_seed
      << ", merge_gap_px: " << Fixed(r.merge_gap_px, 6) << "}\n";
  out << "frames:\n";
  for (const SequenceTruthFrame& f : t.frames) {
    out << "  - image: " << Quoted(f.image) << "\n    pose_id: " << Quoted(f.pose_id)
        << "\n    pose_index: " << f.pose_index << "\n    sequence: " << f.sequence
        << "\n    exposure_time_s: " << Fixed(f.exposure_time_s, 9) << "\n    dots:\n";
    for (const SequenceTruthDot& d : f.dots) {
      std::string flags;
      const std::pair<bool, const char*> named[] = {{d.in_front, "in_front"},         {d.visible, "visible"},
                                                    {d.fully_inside, "fully_inside"}, {d.clipped, "clipped"},
                                                    {d.overlapping, "overlapping"},   {d.near_other, "near_other"}};
      for (const auto& [set, name] : named) {
        if (set) flags += (flags.empty() ? "" : ", ") + std::string(name);
      }
      out << "      - {id: " << d.id << ", projected_centre_px: " << Pair(d.projected_centre_px)
          << ", area_centroid_px: " << Pair(d.area_centroid_px) << ", area_px2: " << Fixed(d.area_px2, 4)
          << ", flags: [" << flags << "]}\n";
    }
  }
  return out.str();
}

// yaml-cpp access that names the key on failure.
class TruthReader {
 public:
  explicit TruthReader(std::string path) : path_(std::move(path)) {}
  YAML::Node Get(const YAML::Node& map, const std::string& key, const std::string& where) const {
    const YAML::Node node = map[key];
    if (!node) throw std::runtime_error(where + key + " is missing");
    return node;
  }
  template <typename T>
  T As(const YAML::Node& map, const std::string& key, const std::string& where) const {
    const YAML::Node node = Get(map, key, where);
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      throw std::runtime_error(where + key + " (line " + std::to_string(node.Mark().line + 1) +
                               ") has the wrong type: `" +
                               (node.IsScalar() ? node.Scalar() : std::string("not a scalar")) + "`");
    }
  }
  Eigen::Vector2d Vec2(const YAML::Node& map, const std::string& key, const std::string& where) const {
    const YAML::Node node = Get(map, key, where);
    if (!node.IsSequence() || node.size() != 2) throw std::runtime_error(where + key + " must be [u, v]");
    return Eigen::Vector2d(node[0].as<double>(), node[1].as<double>());
  }

 private:
  std::string path_;
};

}  // namespace

std::string SequenceRenderOptions::Validate() const {
  std::ostringstream out;
  out << render.Validate();
  if (!std::isfinite(dot_radius_m) || dot_radius_m <= 0) out << "dot_radius_m = " << dot_radius_m << " must be > 0\n";
  if (!std::isfinite(frame_period_s) || frame_period_s <= 0) out << "frame_period_s must be > 0\n";
  if (!std::isfinite(pose_interval_s) || pose_interval_s <= frame_period_s)
    out << "pose_interval_s must exceed frame_period_s\n";
  if (!std::isfinite(settle_s) || settle_s < 0 || settle_s + frame_period_s >= pose_interval_s) {
    out << "settle_s = " << settle_s << " must lie in [0, pose_interval_s - frame_period_s)\n";
  }
  if (!std::isfinite(first_pose_time_s)) out << "first_pose_time_s must be finite\n";
  if (png_compression < 0 || png_compression > 9) out << "png_compression must lie in [0, 9]\n";
  return out.str();
}

Status RenderSequenceFolder(const SimResult& world, const SequenceRenderOptions& options, const std::string& folder,
                            SequenceTruth* truth_out) {
  if (const std::string problems = options.Validate(); !problems.empty()) {
    return Status::Error(ErrorCode::kInvalidInput, "invalid sequence rendering options:\n" + problems);
  }
  if (!world.ok) return Status::Error(ErrorCode::kInvalidInput, "cannot render a failed simulation: " + world.message);
  const SimTruth& truth = world.truth;
  std::vector<int> poses = options.pose_indices;
  if (poses.empty()) {
    for (size_t i = 0; i < truth.base_from_cam.size(); ++i) poses.push_back(static_cast<int>(i));
  }
  for (const int i : poses) {
    if (i < 0 || i >= static_cast<int>(truth.base_from_cam.size())) {
      return Status::Error(ErrorCode::kInvalidInput, "pose index " + std::to_string(i) + " outside the world's " +
                                                 std::to_string(truth.base_from_cam.size()) + " poses");
    }
  }
  SimulatedCameraOptions camera_options;
  camera_options.render = options.render;
  camera_options.frame_period_s = options.frame_period_s;
  camera_options.first_exposure_s = 0.0;
  SimulatedCamera camera(truth.camera_true, MakeDotScene(truth, options.dot_radius_m), camera_options);
  if (Status s = camera.Open(); !s.ok()) return s;
  Result<capture::RecordedSequenceWriter> writer = capture::RecordedSequenceWriter::Create(
      folder, truth.camera_true.width_px, truth.camera_true.height_px, options.png_compression);
  if (!writer.ok()) return writer.status();

  SequenceTruth out;
  out.world_description = options.world_description;
  out.camera = truth.camera_true;
  out.dot_radius_m = options.dot_radius_m;
  out.render = options.render;
  for (size_t n = 0; n < poses.size(); ++n) {
    const int i = poses[n];
    const double arrival = options.first_pose_time_s + static_cast<double>(n) * options.pose_interval_s;
    camera.SetPose(truth.base_from_cam[i], arrival);
    Result<capture::Frame> frame = camera.Grab(arrival + options.settle_s, 1.0);
    if (!frame.ok()) return frame.status();
    const std::string pose_id = i < static_cast<int>(world.observations.poses.size()) ? world.observations.poses[i].id
                                                                                      : "pose" + std::to_string(i);
    if (Status s = writer.value().Append(*frame, pose_id); !s.ok()) return s;
    SequenceTruthFrame f;
    f.image = writer->index().frames.back().image;
    f.pose_id = pose_id;
    f.pose_index = i;
    f.sequence = frame->sequence;
    f.exposure_time_s = frame->exposure_time_s;
    for (const RenderedDot& d : camera.last_render().dots) {
      SequenceTruthDot t;
      t.id = d.id;
      t.projected_centre_px = d.projected_centre_px;
      t.area_centroid_px = d.area_centroid_px;
      t.area_px2 = d.area_px2;
      t.in_front = d.in_front;
      t.visible = d.visible;
      t.fully_inside = d.fully_inside;
      t.clipped = d.clipped;
      t.overlapping = d.overlapping;
      t.near_other = d.near_other;
      f.dots.push_back(t);
    }
    out.frames.push_back(std::move(f));
  }
  if (Status s = writer.value().WriteAuxiliaryFile(kSequenceTruthName, FormatTruth(out)); !s.ok()) return s;
  if (truth_out != nullptr) *truth_out = std::move(out);
  return Status::Ok();
}

Result<SequenceTruth> ReadSequenceTruth(const std::string& path) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0)
    return Status::Error(ErrorCode::kInvalidInput, "cannot read truth file " + path + ": no such file");
  if (!S_ISREG(st.st_mode) || st.st_size > kMaxTruthBytes) {
    return Status::Error(ErrorCode::kInvalidInput,
                         path + " is not a regular file of at most " + std::to_string(kMaxTruthBytes) + " bytes");
  }
  SequenceTruth t;
  try {
    const YAML::Node root = YAML::LoadFile(path);
    const TruthReader r(path);
    if (r.As<std::string>(root, "format", "") != kTruthFormat || r.As<int>(root, "format_version", "") != 1) {
      throw std::runtime_error("not a selfcal-sequence-truth file of version 1");
    }
    t.world_description = r.As<std::string>(root, "world", "");
    const YAML::Node cam = r.Get(root, "camera", "");
    t.camera.width_px = r.As<int>(cam, "width_px", "camera.");
    t.camera.height_px = r.As<int>(cam, "height_px", "camera.");
    t.camera.fx_px = r.As<double>(cam, "fx_px", "camera.");
    t.camera.mu = r.As<double>(cam, "mu", "camera.");
    t.camera.cx_px = r.As<double>(cam, "cx_px", "camera.");
    t.camera.cy_px = r.As<double>(cam, "cy_px", "camera.");
    t.camera.k1 = r.As<double>(cam, "k1", "camera.");
    t.dot_radius_m = r.As<double>(root, "dot_radius_m", "");
    const YAML::Node render = r.Get(root, "render", "");
    t.render.supersampling = r.As<int>(render, "supersampling", "render.");
    t.render.background_grey = r.As<double>(render, "background_grey", "render.");
    t.render.dot_grey = r.As<double>(render, "dot_grey", "render.");
    t.render.blur_sigma_px = r.As<double>(render, "blur_sigma_px", "render.");
    t.render.noise_std_grey = r.As<double>(render, "noise_std_grey", "render.");
    t.render.noise_seed = r.As<uint64_t>(render, "noise_seed", "render.");
    t.render.merge_gap_px = r.As<double>(render, "merge_gap_px", "render.");
    const YAML::Node frames = r.Get(root, "frames", "");
    for (size_t i = 0; i < frames.size(); ++i) {
      const YAML::Node f = frames[i];
      const std::string where = "frames[" + std::to_string(i) + "].";
      SequenceTruthFrame frame;
      frame.image = r.As<std::string>(f, "image", where);
      frame.pose_id = r.As<std::string>(f, "pose_id", where);
      frame.pose_index = r.As<int>(f, "pose_index", where);
      frame.sequence = r.As<int64_t>(f, "sequence", where);
      frame.exposure_time_s = r.As<double>(f, "exposure_time_s", where);
      const YAML::Node dots = r.Get(f, "dots", where);
      for (size_t k = 0; k < dots.size(); ++k) {
        const YAML::Node d = dots[k];
        const std::string at = where + "dots[" + std::to_string(k) + "].";
        SequenceTruthDot dot;
        dot.id = r.As<int>(d, "id", at);
        dot.projected_centre_px = r.Vec2(d, "projected_centre_px", at);
        dot.area_centroid_px = r.Vec2(d, "area_centroid_px", at);
        dot.area_px2 = r.As<double>(d, "area_px2", at);
        const YAML::Node flags = r.Get(d, "flags", at);
        if (!flags.IsSequence()) throw std::runtime_error(at + "flags must be a list");
        for (const YAML::Node& flag : flags) {
          const std::string name = flag.as<std::string>();
          bool* target = name == "in_front"       ? &dot.in_front
                         : name == "visible"      ? &dot.visible
                         : name == "fully_inside" ? &dot.fully_inside
                         : name == "clipped"      ? &dot.clipped
                         : name == "overlapping"  ? &dot.overlapping
                         : name == "near_other"   ? &dot.near_other
                                                  : nullptr;
          if (target == nullptr) throw std::runtime_error(at + "flags: unknown flag `" + name + "`");
          *target = true;
        }
        frame.dots.push_back(dot);
      }
      t.frames.push_back(std::move(frame));
    }
  } catch (const YAML::Exception& e) {
    return Status::Error(ErrorCode::kInvalidInput, "malformed truth file " + path + ": " + e.what());
  } catch (const std::exception& e) {
    return Status::Error(ErrorCode::kInvalidInput, "truth file " + path + ": " + e.what());
  }
  return t;
}

}  // namespace selfcal::sim
