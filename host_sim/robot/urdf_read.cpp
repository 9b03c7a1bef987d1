#include "robot/urdf_read.hpp"

#include <console_bridge/console.h>
#include <tinyxml.h>

#include <Eigen/Dense>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "io/recording.hpp"
#include "io/utf8.hpp"

namespace jg::robot {
namespace {

[[noreturn]] void refuse(const std::string& path, const std::string& what) { throw io::FormatError(path + ": " + what); }

// --- Reading: urdfdom, with its logging kept away from printf formats ----------------

/// Collects urdfdom's error messages instead of printing them.
class CaptureErrors : public console_bridge::OutputHandler {
 public:
  void log(const std::string& text, console_bridge::LogLevel level, const char* /*file*/, int /*line*/) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_ERROR) errors.push_back(text);
  }
  std::vector<std::string> errors;
};

/// Restores console_bridge's handler and level on every way out.
class LoggingGuard {
 public:
  LoggingGuard() : level_(console_bridge::getLogLevel()) {}
  ~LoggingGuard() {
    if (handler_set_) console_bridge::restorePreviousOutputHandler();
    console_bridge::setLogLevel(level_);
  }
  LoggingGuard(const LoggingGuard&) = delete;
  LoggingGuard& operator=(const LoggingGuard&) = delete;
  void capture(console_bridge::OutputHandler* h) {
    console_bridge::useOutputHandler(h);
    handler_set_ = true;
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_ERROR);
  }
  void silence() {
    if (handler_set_) console_bridge::restorePreviousOutputHandler();
    handler_set_ = false;
    console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);  // no message is formatted at all
  }

 private:
  console_bridge::LogLevel level_;
  bool handler_set_ = false;
};

/// The file's text with every way to a '%' removed ('%' itself and XML character
/// references, which TinyXML decodes): urdfdom hands messages holding the file's text to
/// console_bridge as the printf format, so only such a copy may be parsed with logging on.
std::string without_format_characters(std::string text) {
  for (std::size_t k = 0; k < text.size(); ++k) {
    if (text[k] == '%') text[k] = '?';
    if (text[k] == '&' && k + 1 < text.size() && text[k + 1] == '#') text.replace(k, 1, "&amp;");
  }
  return text;
}

/// urdfdom's links own their children (shared_ptr): a joint whose child is its own parent,
/// or a loop of joints, makes a cycle that is never freed (found by fuzzing, a leak per
/// file read). Clearing the child lists frees it; the model is unusable after this.
void break_cycles(urdf::ModelInterface& m) {
  for (auto& [name, link] : m.links_) {
    if (!link) continue;
    link->child_links.clear();
    link->child_joints.clear();
  }
  m.root_link_.reset();
}

/// The model, owned so that its cycles (if any) are broken when the last user drops it.
urdf::ModelInterfaceSharedPtr owned(urdf::ModelInterfaceSharedPtr m) {
  if (!m) return m;
  urdf::ModelInterface* raw = m.get();
  return {raw, [m](urdf::ModelInterface*) mutable {
            break_cycles(*m);
            m.reset();
          }};
}

/// Refuses text TinyXML (urdfdom's parser) cannot be given: a NUL byte, or bytes that are not
/// UTF-8. TinyXML skips a multi-byte character by the length its lead byte announces, so a
/// lead byte at the end of the file made it read past the buffer (ASan heap-buffer-overflow
/// in TiXmlBase::ReadName, found by fuzzing).
void check_text(const std::string& path, const std::string& text) {
  std::size_t line = 1;
  for (std::size_t k = 0; k < text.size();) {
    const auto c = static_cast<unsigned char>(text[k]);
    if (c == '\n') ++line;
    if (c == 0) refuse(path, "line " + std::to_string(line) + ": a NUL byte: not a text file");
    const std::size_t len = io::utf8_sequence_length(text, k);
    if (len == 0) refuse(path, "line " + std::to_string(line) + ": bytes that are not UTF-8 text (a URDF is XML in UTF-8)");
    k += len;
  }
}

/// Refuses, before urdfdom sees them, joints whose child is their parent, links that are the
/// child of two joints and loops of joints: urdfdom links such a tree into shared_ptr
/// cycles and, when it then refuses the file (e.g. two roots), leaks them (found by
/// fuzzing). Files TinyXML cannot read are left to urdfdom's error.
void check_joint_graph(const std::string& path, const std::string& text) {
  TiXmlDocument doc;
  doc.Parse(text.c_str());
  const TiXmlElement* robot = doc.Error() ? nullptr : doc.FirstChildElement("robot");
  if (robot == nullptr) return;
  std::map<std::string, std::string> parent_of;
  for (const TiXmlElement* j = robot->FirstChildElement("joint"); j != nullptr; j = j->NextSiblingElement("joint")) {
    const TiXmlElement* p = j->FirstChildElement("parent");
    const TiXmlElement* c = j->FirstChildElement("child");
    const char* name = j->Attribute("name");
    if (p == nullptr || c == nullptr || p->Attribute("link") == nullptr || c->Attribute("link") == nullptr) continue;
    const std::string parent = p->Attribute("link"), child = c->Attribute("link");
    const std::string joint = std::string("joint '") + (name ? name : "") + "': ";
    if (parent == child) refuse(path, joint + "its parent and child are the same link '" + child + "'");
    if (!parent_of.emplace(child, parent).second) refuse(path, joint + "link '" + child + "' is already the child of another joint");
  }
  for (const auto& [child, parent] : parent_of) {
    std::string up = parent;
    for (std::size_t steps = 0; steps <= parent_of.size(); ++steps) {
      if (up == child) refuse(path, "link '" + child + "' is its own ancestor: the joints form a loop");
      const auto it = parent_of.find(up);
      if (it == parent_of.end()) break;
      up = it->second;
    }
  }
}

urdf::ModelInterfaceSharedPtr parse(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) refuse(path, "cannot read the file");
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  check_text(path, text);
  // Both texts urdfdom parses: an invalid character reference makes TinyXML refuse the real
  // text but not the harmless copy (found by fuzzing: the copy's loop leaked).
  check_joint_graph(path, text);
  check_joint_graph(path, without_format_characters(text));
  LoggingGuard guard;
  // First pass on the harmless copy, only to hear urdfdom's complaints: it logs some errors
  // (a mass "heavy", a vector "1 2") and goes on with zeros.
  CaptureErrors capture;
  guard.capture(&capture);
  const std::string harmless = without_format_characters(text);
  bool copy_parsed = false;
  try {
    copy_parsed = owned(urdf::parseURDF(harmless)) != nullptr;
  } catch (const std::exception& e) {  // urdfdom mostly logs, but may throw (version attribute)
    capture.errors.emplace_back(e.what());
  }
  guard.silence();
  if (!capture.errors.empty()) {
    std::string all;
    for (const auto& e : capture.errors) all += (all.empty() ? "" : "; ") + e;
    refuse(path, "not a valid URDF: " + all + (harmless != text ? " (the file's '%' shown as '?')" : ""));
  }
  urdf::ModelInterfaceSharedPtr model;
  try {
    model = owned(urdf::parseURDF(text));
  } catch (const std::exception& e) {
    refuse(path, std::string("not a valid URDF: ") + e.what());
  }
  if (!model || !copy_parsed) refuse(path, "not a valid URDF (urdfdom could not read it)");
  return model;
}

// --- Checks on the values urdfdom read ------------------------------------------------

bool finite(const urdf::Vector3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool finite(const urdf::Pose& p) {
  return finite(p.position) && std::isfinite(p.rotation.x) && std::isfinite(p.rotation.y) &&
         std::isfinite(p.rotation.z) && std::isfinite(p.rotation.w);
}

void check_inertial(const std::string& path, const urdf::Link& link) {
  if (!link.inertial) return;
  const urdf::Inertial& in = *link.inertial;
  const std::string where = "link '" + link.name + "': <inertial>: ";
  if (!finite(in.origin)) refuse(path, where + "<origin> is not finite");
  const double v[] = {in.mass, in.ixx, in.iyy, in.izz, in.ixy, in.ixz, in.iyz};
  for (const double x : v) {
    if (!std::isfinite(x)) refuse(path, where + "<mass>/<inertia> values must be finite numbers");
  }
  if (in.mass < 0.0) refuse(path, where + "<mass value> must be >= 0");
  // A body's inertia is positive semi-definite and obeys the triangle inequalities (its
  // principal moments are sums of non-negative second moments).
  Eigen::Matrix3d I;
  I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  const Eigen::Vector3d l = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(I).eigenvalues();
  const double tol = 1e-6 * std::max(l.cwiseAbs().maxCoeff(), 1e-12);
  if (l(0) < -tol || l(0) + l(1) < l(2) - tol) {
    std::ostringstream s;
    s << where << "<inertia> is not a physical inertia (principal moments " << l(0) << ", " << l(1) << ", " << l(2)
      << " kg m^2: must be >= 0 and each at most the sum of the other two)";
    refuse(path, s.str());
  }
}

void check_joint(const std::string& path, const urdf::Joint& j) {
  const std::string where = "joint '" + j.name + "': ";
  if (!finite(j.parent_to_joint_origin_transform)) refuse(path, where + "<origin> is not finite");
  if (!finite(j.axis)) refuse(path, where + "<axis xyz> is not finite");
  if (j.limits) {
    const double v[] = {j.limits->lower, j.limits->upper, j.limits->effort, j.limits->velocity};
    for (const double x : v) {
      if (!std::isfinite(x)) refuse(path, where + "<limit> values must be finite numbers");
    }
  }
}

}  // namespace

/// Refuses links that are their own ancestor (a joint from a link to itself, a loop of
/// joints): urdfdom accepts them when another link is the root.
void check_tree(const std::string& path, const urdf::ModelInterface& m) {
  for (const auto& [name, link] : m.links_) {
    std::size_t steps = 0;
    for (urdf::LinkSharedPtr up = link->getParent(); up; up = up->getParent()) {
      if (up == link || ++steps > m.links_.size()) refuse(path, "link '" + name + "' is its own ancestor: the joints form a loop");
    }
  }
}

urdf::ModelInterfaceSharedPtr read_urdf(const std::string& path) {
  urdf::ModelInterfaceSharedPtr model = parse(path);
  check_tree(path, *model);
  for (const auto& [name, link] : model->links_) check_inertial(path, *link);
  for (const auto& [name, joint] : model->joints_) check_joint(path, *joint);
  return model;
}

}  // namespace jg::robot
