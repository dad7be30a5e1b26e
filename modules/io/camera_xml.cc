#include "io/camera_xml.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "base/xml_scan.h"
#include "io/yaml_schema.h"

namespace selfcal::io {

namespace {

struct XmlElement {
  std::string name;
  std::string text;  // character data directly inside, entities decoded, trimmed
  int line = 0;
  int text_line = 0;  // of its first character data that is not white space (0: none)
  std::vector<XmlElement> children;
};

std::string Trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t\r\n");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t\r\n") - a + 1);
}

std::string Decode(const std::string& s) {
  static const std::pair<const char*, char> kEntities[] = {{"&lt;", '<'}, {"&gt;", '>'}, {"&amp;", '&'},
                                                           {"&quot;", '"'}, {"&apos;", '\''}};
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    bool replaced = false;
    for (const auto& [entity, c] : kEntities) {
      const size_t n = std::char_traits<char>::length(entity);
      if (s.compare(i, n, entity) == 0) {
        out += c;
        i += n - 1;
        replaced = true;
        break;
      }
    }
    if (!replaced) out += s[i];
  }
  return out;
}

// Why the comment or declaration at s[i] is not well-formed XML, or "": `--` inside a comment (XML 1.0
// allows none; a comment's lines moved or repeated leave one), an XML declaration without `version=`.
std::string MarkupProblem(const std::string& s, size_t i) {
  if (s.compare(i, 4, "<!--") == 0) {
    const size_t end = s.find("-->", i + 4);
    return s.find("--", i + 4) < end ? "`--` inside a comment (XML allows none: were a comment's lines moved?)" : "";
  }
  if (s.compare(i, 5, "<?xml") != 0 || i + 5 >= s.size() || s.find_first_of(" \t\r\n", i + 5) != i + 5) return "";
  const size_t name = s.find_first_not_of(" \t\r\n", i + 5);
  const size_t equals = name == std::string::npos ? name : s.find_first_not_of(" \t\r\n", name + 7);
  if (s.compare(name == std::string::npos ? s.size() : name, 7, "version") == 0 && equals != std::string::npos &&
      s[equals] == '=') {
    return "";
  }
  return "the XML declaration must begin `<?xml version=`";
}

// Parses `s` into the single top-level element. Returns an error message, its line in *error_line, or "".
std::string ParseXml(const std::string& s, XmlElement* top, int* error_line) {
  const auto fail = [error_line](int at, const std::string& why) {
    *error_line = at;
    return why;
  };
  std::vector<XmlElement> stack;
  std::vector<XmlElement> tops;
  int line = 1;
  auto advance = [&](size_t from, size_t to) { line += static_cast<int>(std::count(s.begin() + from, s.begin() + to, '\n')); };
  size_t i = 0;
  while (i < s.size()) {
    if (s[i] != '<') {
      const size_t next = std::min(s.find('<', i), s.size());
      const std::string text = s.substr(i, next - i);
      if (stack.empty()) {
        if (!Trim(text).empty()) return fail(line, "text outside the root element");
      } else {
        const size_t first = text.find_first_not_of(" \t\r\n");
        if (first != std::string::npos && stack.back().text_line == 0) {
          stack.back().text_line = line + static_cast<int>(std::count(text.begin(), text.begin() + first, '\n'));
        }
        stack.back().text += text;
      }
      advance(i, next);
      i = next;
      continue;
    }
    const auto skip_to = [&](const std::string& end) -> bool {
      const size_t close = s.find(end, i);
      if (close == std::string::npos) return false;
      advance(i, close + end.size());
      i = close + end.size();
      return true;
    };
    if (const std::string problem = MarkupProblem(s, i); !problem.empty()) return fail(line, problem);
    if (s.compare(i, 4, "<!--") == 0) {
      if (!skip_to("-->")) return fail(line, "unterminated comment");
      continue;
    }
    if (s.compare(i, 2, "<?") == 0) {
      if (!skip_to("?>")) return fail(line, "unterminated declaration");
      continue;
    }
    if (s.compare(i, 2, "<!") == 0) return fail(line, "DTDs and CDATA sections are not accepted");
    const size_t close = s.find('>', i);
    if (close == std::string::npos) return fail(line, "unterminated tag");
    std::string tag = Trim(s.substr(i + 1, close - i - 1));
    const int tag_line = line;
    advance(i, close + 1);
    i = close + 1;
    if (!tag.empty() && tag[0] == '/') {
      const std::string name = Trim(tag.substr(1));
      if (stack.empty() || stack.back().name != name) {
        return fail(tag_line, "closing tag </" + name + "> does not match" +
               (stack.empty() ? std::string(" any open element") : " <" + stack.back().name + ">"));
      }
      XmlElement done = std::move(stack.back());
      stack.pop_back();
      done.text = Decode(Trim(done.text));
      const bool container = done.name == "root" || done.name == "camera" || done.name == "model";  // hold elements only
      if (container && !done.text.empty()) {  // a value element holding one is refused by CheckLeaves
        return fail(done.text_line, "text `" + done.text.substr(0, std::min(done.text.find('\n'), size_t{60})) +
                                        "` between the elements of <" + done.name + ">");
      }
      (stack.empty() ? tops : stack.back().children).push_back(std::move(done));
      continue;
    }
    const bool self_closing = !tag.empty() && tag.back() == '/';
    if (self_closing) tag = Trim(tag.substr(0, tag.size() - 1));
    if (tag.empty() || tag.find_first_of(" \t\r\n=\"'") != std::string::npos) {
      return fail(tag_line, "<" + tag + "> is not a plain element (attributes are not accepted)");
    }
    XmlElement e;
    e.name = tag;
    e.line = tag_line;
    if (self_closing) {
      (stack.empty() ? tops : stack.back().children).push_back(std::move(e));
    } else {
      stack.push_back(std::move(e));
    }
  }
  if (!stack.empty()) return fail(stack.back().line, "element <" + stack.back().name + "> is never closed");
  if (tops.size() != 1) {
    return fail(tops.empty() ? line : tops[1].line,
                "the document must have exactly one root element (found " + std::to_string(tops.size()) + ")");
  }
  *top = std::move(tops[0]);
  return "";
}

// Checks the children of `e` against `allowed` (each at most once unless in `repeatable`).
void CheckChildren(const XmlElement& e, const std::vector<std::string>& allowed, const std::vector<std::string>& repeatable,
                   Problems* problems) {
  std::vector<std::string> seen;
  for (const XmlElement& c : e.children) {
    if (std::find(allowed.begin(), allowed.end(), c.name) == allowed.end()) {
      std::string best;
      int best_distance = 1 << 30;
      for (const std::string& a : allowed) {
        const int d = EditDistance(c.name, a);
        if (d < best_distance) best_distance = d, best = a;
      }
      std::string message = "unknown element <" + c.name + "> in <" + e.name + "> at " + problems->At(c.line);
      if (best_distance <= std::max<int>(2, static_cast<int>(c.name.size()) / 3)) message += "; did you mean <" + best + ">?";
      problems->Add(message);
    } else if (std::find(repeatable.begin(), repeatable.end(), c.name) == repeatable.end() &&
               std::find(seen.begin(), seen.end(), c.name) != seen.end()) {
      problems->Add("element <" + c.name + "> repeated in <" + e.name + "> at " + problems->At(c.line));
    }
    seen.push_back(c.name);
  }
}

// The children of `e` that hold a value (all but those in `containers`) hold text only: an element inside
// <type> or <px> is refused (its text around the element would otherwise be read as the value).
void CheckLeaves(const XmlElement& e, const std::vector<std::string>& containers, Problems* problems) {
  for (const XmlElement& c : e.children) {
    if (c.children.empty() || std::find(containers.begin(), containers.end(), c.name) != containers.end()) continue;
    problems->Add("element <" + c.children[0].name + "> inside <" + c.name + "> at " + problems->At(c.children[0].line) +
                  ": <" + c.name + "> holds a value, not elements");
  }
}

const XmlElement* Child(const XmlElement& e, const std::string& name) {
  for (const XmlElement& c : e.children) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

bool ReadNumber(const XmlElement& parent, const std::string& name, bool required, Problems* problems, double* out) {
  const XmlElement* c = Child(parent, name);
  if (c == nullptr) {
    if (required) problems->Add("missing element <" + name + "> in <" + parent.name + "> at " + problems->At(parent.line));
    return !required;
  }
  errno = 0;
  char* end = nullptr;
  const double v = std::strtod(c->text.c_str(), &end);
  if (c->text.empty() || end != c->text.c_str() + c->text.size() || errno == ERANGE || !std::isfinite(v)) {
    problems->Add("<" + name + "> = `" + c->text + "` at " + problems->At(c->line) + " is not a finite number");
    return false;
  }
  *out = v;
  return true;
}

bool ReadSize(const XmlElement& camera, const std::string& name, Problems* problems, int* out) {
  double v = 0;
  if (!ReadNumber(camera, name, true, problems, &v)) return false;
  if (v != std::floor(v) || v < 1 || v > 100000) {
    problems->Add("<" + name + "> at " + problems->At(Child(camera, name)->line) +
                  " must be an integer in [1, 100000] (selfcal needs the image size the camera was calibrated at)");
    return false;
  }
  *out = static_cast<int>(v);
  return true;
}

constexpr const char* kWithDistortion = "perspectiveProjWithDistortion";
constexpr const char* kWithoutDistortion = "perspectiveProjWithoutDistortion";

// The model to use: with distortion when present, else without; refuses other model types.
const XmlElement* ChooseModel(const XmlElement& camera, Problems* problems) {
  const XmlElement* with = nullptr;
  const XmlElement* without = nullptr;
  for (const XmlElement& m : camera.children) {
    if (m.name != "model") continue;
    const XmlElement* type = Child(m, "type");
    if (type == nullptr) {
      problems->Add("missing element <type> in <model> at " + problems->At(m.line));
    } else if (type->text == kWithDistortion) {
      with = &m;
    } else if (type->text == kWithoutDistortion) {
      without = &m;
    } else {
      problems->Add("<type> `" + type->text + "` at " + problems->At(type->line) + ": selfcal reads only " + kWithoutDistortion +
                    " and " + kWithDistortion + " (a Kannala-Brandt or other fisheye model is not selfcal's)");
    }
    CheckChildren(m, {"type", "px", "py", "u0", "v0", "kud", "kdu"}, {}, problems);
    CheckLeaves(m, {}, problems);
  }
  if (with == nullptr && without == nullptr && problems->empty()) {
    problems->Add("camera at " + problems->At(camera.line) + " has no <model>");
  }
  return with != nullptr ? with : without;
}

}  // namespace

Result<CameraIntrinsics> ParseVispCameraXml(const std::string& path, const std::string& contents,
                                            const std::string& camera_name) {
  Problems problems(path);
  // Before the tree is built (a tree of 100,000 nested elements overflows the stack when it is destroyed):
  // size, depth, UTF-8 and tags closed, by line.
  XmlScanLimits limits;
  limits.kind = "a ViSP camera file";
  limits.require_utf8 = true;
  if (Status s = ScanXml(contents, path, limits); !s.ok()) {
    return Status::Error(ErrorCode::kInvalidInput, "cannot read " + path + " as a ViSP camera file: " + s.message());
  }
  XmlElement root;
  int error_line = 1;
  if (const std::string error = ParseXml(contents, &root, &error_line); !error.empty()) {
    return Status::Error(ErrorCode::kInvalidInput,
                         "cannot read " + path + " as a ViSP camera file: " + problems.At(error_line) + ": " + error);
  }
  if (root.name != "root") {
    return Status::Error(ErrorCode::kInvalidInput, "cannot read " + path + " as a ViSP camera file: the root element <" +
                                                       root.name + "> at " + problems.At(root.line) + " is not <root>");
  }
  CheckChildren(root, {"camera"}, {"camera"}, &problems);
  std::vector<const XmlElement*> cameras;
  std::vector<std::string> names;
  for (const XmlElement& c : root.children) {
    if (c.name != "camera") continue;
    const XmlElement* name = Child(c, "name");
    names.push_back(name != nullptr ? name->text : "");
    if (camera_name.empty() || names.back() == camera_name) cameras.push_back(&c);
  }
  std::string list;
  for (const std::string& n : names) list += (list.empty() ? "`" : ", `") + n + "`";
  if (names.empty()) problems.Add("no <camera> in <root> at " + problems.At(root.line));
  if (!names.empty() && cameras.empty()) {
    problems.Add("no camera named `" + camera_name + "` in <root> at " + problems.At(root.line) + " (cameras: " + list +
                 ")");
  } else if (cameras.size() > 1) {
    problems.Add(camera_name.empty() ? path + " holds several cameras (" + list + "); choose one by name (the second at " +
                                           problems.At(cameras[1]->line) + ")"
                                     : "camera `" + camera_name + "` appears more than once in " + path + " (again at " +
                                           problems.At(cameras[1]->line) + ")");
  }
  if (!problems.empty() || cameras.size() != 1) return problems.ToStatus("camera intrinsics");
  const XmlElement& camera = *cameras[0];
  CheckChildren(camera, {"name", "image_width", "image_height", "subsampling_width", "subsampling_height", "full_width",
                         "full_height", "model", "additional_information"},
                {"model"}, &problems);
  CheckLeaves(camera, {"model", "additional_information"}, &problems);
  CameraIntrinsics out;
  ReadSize(camera, "image_width", &problems, &out.width_px);
  ReadSize(camera, "image_height", &problems, &out.height_px);
  for (const char* subsampling : {"subsampling_width", "subsampling_height"}) {
    double s = 1;
    if (ReadNumber(camera, subsampling, false, &problems, &s) && s != 1 && s != 0) {
      problems.Add("<" + std::string(subsampling) + "> = " + Child(camera, subsampling)->text + " at " +
                   problems.At(Child(camera, subsampling)->line) + ": subsampled intrinsics are not accepted");
    }
  }
  const XmlElement* model = ChooseModel(camera, &problems);
  if (model == nullptr) return problems.ToStatus("camera intrinsics");
  double py = 0, kud = 0, kdu = 0;
  bool ok = ReadNumber(*model, "px", true, &problems, &out.fx_px);
  ok &= ReadNumber(*model, "py", true, &problems, &py);
  ok &= ReadNumber(*model, "u0", true, &problems, &out.cx_px);
  ok &= ReadNumber(*model, "v0", true, &problems, &out.cy_px);
  const bool distortion = Child(*model, "type")->text == kWithDistortion;
  ok &= ReadNumber(*model, "kud", distortion, &problems, &kud);
  ok &= ReadNumber(*model, "kdu", distortion, &problems, &kdu);
  if (!distortion && (Child(*model, "kud") != nullptr || Child(*model, "kdu") != nullptr)) {
    problems.Add("<model> at " + problems.At(model->line) + " is " + kWithoutDistortion + " but has <kud> or <kdu>");
  }
  if (ok && !(out.fx_px > 0 && py > 0)) problems.Add("<px> and <py> at " + problems.At(model->line) + " must be > 0");
  if (!problems.empty()) return problems.ToStatus("camera intrinsics");
  out.mu = py / out.fx_px;
  // ViSP projects u = u0 + px x (1 + kud r^2): OpenCV's model with k1 = kud, exactly. kdu is ViSP's separate
  // approximate inverse; selfcal inverts the projection itself.
  out.k1 = kud;
  std::istringstream invalid(out.Validate());
  for (std::string line; std::getline(invalid, line);) problems.Add(problems.At(model->line) + ": " + line);
  if (!problems.empty()) return problems.ToStatus("camera intrinsics");
  return out;
}

}  // namespace selfcal::io
