// The JSON reading shared by the scene parser's files (scene.cpp, articulation.cpp): a value
// with its path in the document, so that every check names where it failed. Internal.
#pragma once

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "mlcp/input_limits.hpp"
#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/scene_limits.hpp"

namespace mlcp::scene::parse {

using nlohmann::json;

constexpr double kPi = 3.14159265358979323846;
// A typo such as "count": 1e6 should fail fast rather than allocate for minutes.
constexpr long long kMaxGeneratedBodies = limits::kMaxBodies;

inline double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }

inline std::string shortDump(const json& v) {
  std::string s = v.dump();
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

// Names and keys come from the file: quoted capped, so that a message stays one short line.
inline std::string inQuotes(const std::string& s) { return "\"" + io::capped(s) + "\""; }

inline std::string joinNames(std::initializer_list<const char*> names) {
  std::string s;
  for (const char* n : names) s += std::string(s.empty() ? "" : ", ") + n;
  return s;
}

// A JSON value together with its path in the document, so that every check can name where it
// failed: "bodies[3].shape.size".
class Node {
 public:
  Node(const json& value, std::string path, const std::string& source)
      : v_(value), path_(std::move(path)), source_(source) {}

  [[noreturn]] void fail(const std::string& what) const {
    const std::string where =
        path_.empty() ? "top level" : io::capped(path_, 2 * io::kMaxEchoChars);
    throw FormatError(source_ + ": " + where + ": " + what);
  }

  const json& value() const { return v_; }
  const std::string& path() const { return path_; }

  const Node& requireObject() const {
    if (!v_.is_object()) fail("expected an object, got " + shortDump(v_));
    return *this;
  }
  bool has(const char* key) const { return v_.is_object() && v_.contains(key); }
  Node at(const char* key) const {
    requireObject();
    if (!v_.contains(key)) fail(std::string("missing field \"") + key + "\"");
    return child(key);
  }
  Node child(const std::string& key) const {
    return Node(v_.at(key), path_.empty() ? key : path_ + "." + key, source_);
  }
  std::size_t arraySize() const {
    if (!v_.is_array()) fail("expected an array, got " + shortDump(v_));
    return v_.size();
  }
  Node item(std::size_t i) const {
    return Node(v_.at(i), path_ + "[" + std::to_string(i) + "]", source_);
  }

  // Keys outside `allowed` (and "comment", allowed everywhere) are errors: they are typos.
  void allowOnly(std::initializer_list<const char*> allowed) const {
    requireObject();
    for (auto it = v_.begin(); it != v_.end(); ++it) {
      if (it.key() == "comment") continue;
      bool known =
          std::any_of(allowed.begin(), allowed.end(), [&](const char* a) { return it.key() == a; });
      if (!known)
        fail("unknown field " + inQuotes(it.key()) + " (allowed here: " + joinNames(allowed) + ")");
    }
  }
  void forbid(const char* key, const std::string& why) const {
    if (has(key)) child(key).fail("not allowed: " + why);
  }

  double number() const {
    if (!v_.is_number()) fail("expected a number, got " + shortDump(v_));
    double d = v_.get<double>();
    if (!std::isfinite(d)) fail("expected a finite number, got " + shortDump(v_));
    return d;
  }
  double positive() const {
    double d = number();
    if (d <= 0) fail("expected a positive number, got " + shortDump(v_));
    return d;
  }
  double nonNegative() const {
    double d = number();
    if (d < 0) fail("expected a number >= 0, got " + shortDump(v_));
    return d;
  }
  double inRange(double lo, double hi) const {
    double d = number();
    if (d < lo || d > hi) {
      std::ostringstream os;
      os << "expected a number in [" << lo << ", " << hi << "], got " << shortDump(v_);
      fail(os.str());
    }
    return d;
  }
  long long integer(long long min, long long max) const {
    double d = v_.is_number() ? v_.get<double>() : NAN;
    if (!v_.is_number() || d != std::floor(d) || d < double(min) || d > double(max))
      fail("expected an integer in [" + std::to_string(min) + ", " + std::to_string(max) +
           "], got " + shortDump(v_));
    return static_cast<long long>(d);
  }
  std::string string() const {
    if (!v_.is_string() || v_.get<std::string>().empty())
      fail("expected a non-empty string, got " + shortDump(v_));
    return v_.get<std::string>();
  }
  bool boolean() const {
    if (!v_.is_boolean()) fail("expected true or false, got " + shortDump(v_));
    return v_.get<bool>();
  }
  Vec3 vec3(const char* what = "3 numbers") const {
    if (!v_.is_array() || v_.size() != 3 ||
        !std::all_of(v_.begin(), v_.end(), [](const json& e) { return e.is_number(); }))
      fail(std::string("expected ") + what + ", got " + shortDump(v_));
    Vec3 r{v_[0].get<double>(), v_[1].get<double>(), v_[2].get<double>()};
    if (!std::all_of(r.begin(), r.end(), [](double d) { return std::isfinite(d); }))
      fail(std::string("expected ") + what + ", got " + shortDump(v_));
    return r;
  }
  Vec3 positiveVec3() const {
    Vec3 r = vec3("3 positive numbers");
    if (!std::all_of(r.begin(), r.end(), [](double d) { return d > 0; }))
      fail("expected 3 positive numbers, got " + shortDump(v_));
    return r;
  }
  Vec3 unitVec3() const {
    Vec3 r = vec3("a direction (3 numbers, not all 0)");
    // Scaled by the largest component first: the norm of [-1e308, -1, 0] overflows.
    const double big = std::max({std::abs(r[0]), std::abs(r[1]), std::abs(r[2])});
    if (big > 0) r = {r[0] / big, r[1] / big, r[2] / big};
    double n = norm(r);
    if (n < 1e-12) fail("expected a direction (3 numbers, not all 0), got " + shortDump(v_));
    return {r[0] / n, r[1] / n, r[2] / n};
  }

 private:
  const json& v_;
  std::string path_;
  const std::string& source_;
};

// Optional fields: the default when absent, else the checked value.
inline double numberOr(const Node& n, const char* key, double fallback,
                       double (Node::*get)() const) {
  return n.has(key) ? (n.child(key).*get)() : fallback;
}
inline Vec3 vec3Or(const Node& n, const char* key, const Vec3& fallback) {
  return n.has(key) ? n.child(key).vec3() : fallback;
}

enum class BodyRole {
  Explicit,           // an entry of "bodies": named by the file
  Template,           // a generator's body: no name or position
  UnrotatedTemplate,  // a stack's or pyramid's body: no orientation either
  Link,               // an articulation's base or link: named by the caller, no velocity
  FixedBase,          // an articulation's fixed base: a Link that is static (mass 0 or none)
};

// A body of the given role; materials resolved against the scene.
Body parseBody(const Node& n, BodyRole role, const Scene& scene);
// "limits" {lower, upper} and "motor" {velocity, max_force} of a hinge or slider.
void parseJointLimitsAndMotor(const Node& n, Joint& j);
// The joint's body named by `n`, a dynamic body of the scene.
int jointBody(const Node& n, const Scene& scene);

// Appends the articulations of the "articulations" array: their bodies to scene.bodies, their
// link joints to scene.joints, their trees to scene.articulations (articulation.hpp).
void parseArticulations(const Node& list, Scene& scene);
// Fails on a joint of the file that touches an articulation's body (`joints` is the file's
// "joints" array, whose entries are scene.joints[first ..)).
void checkArticulationsAlone(const Node& joints, const Scene& scene, std::size_t first);

}  // namespace mlcp::scene::parse
