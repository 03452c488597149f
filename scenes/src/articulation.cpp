// The "articulations" of a scene file: trees of links expanded into bodies and joints
// (mlcp/scene/articulation.hpp).
#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "scene_parse.hpp"

namespace mlcp::scene::parse {

namespace {

// Links per articulation: Featherstone's cost is linear in them, but a typo such as a generated
// list of a million links should fail at once.
constexpr long long kMaxLinks = 1000;

// The parent a link names: an index into "links" (-1 for the base) or a name (the base's, which
// is the articulation's, or a link's). Returns the link index, -1 for the base.
int parentIndex(const Node& link, std::size_t self, const std::vector<std::string>& names,
                const std::string& baseName) {
  const Node p = link.at("parent");
  int index = -1;
  if (p.value().is_number()) {
    const double d = p.value().get<double>();
    if (!(d == std::floor(d) && d >= -1 && d < double(names.size())))
      p.fail("bad parent index " + shortDump(p.value()) + ": expected -1 (the base) to " +
             std::to_string(names.size() - 1) + " (a link of this articulation)");
    index = int(d);
  } else {
    const std::string name = p.string();
    if (name != baseName) {
      const auto it = std::find(names.begin(), names.end(), name);
      if (it == names.end())
        p.fail("no link named " + inQuotes(name) + " in articulation " + inQuotes(baseName) +
               " (a parent is the base, " + inQuotes(baseName) + ", or one of its links)");
      index = int(it - names.begin());
    }
  }
  if (index == int(self)) p.fail("a link cannot be its own parent");
  return index;
}

// The links in parent-first order (parents before children, file order otherwise); fails on a
// cycle, naming a link on it.
std::vector<int> parentFirst(const std::vector<int>& parent, const Node& links,
                             const std::vector<std::string>& names) {
  const int n = int(parent.size());
  std::vector<int> depth(n, -1);  // -1 unknown, -2 on the walk in progress
  for (int k = 0; k < n; ++k) {
    std::vector<int> path;
    int at = k;
    while (at >= 0 && depth[at] == -1) {
      depth[at] = -2;
      path.push_back(at);
      at = parent[at];
    }
    if (at >= 0 && depth[at] == -2)
      links.item(std::size_t(at))
          .child("parent")
          .fail("the parents form a cycle through link " + inQuotes(names[at]));
    int d = at < 0 ? 0 : depth[at] + 1;
    for (auto it = path.rbegin(); it != path.rend(); ++it) depth[*it] = d++;
  }
  std::vector<int> order(n);
  for (int k = 0; k < n; ++k) order[k] = k;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return depth[a] < depth[b]; });
  return order;
}

// The link's joint to its parent body (-1: the world, for a fixed base).
Joint parseLinkJoint(const Node& n, const Body& link, int linkBody, int parentBody) {
  n.requireObject();
  n.allowOnly({"name", "type", "anchor", "axis", "limits", "motor"});
  Joint j;
  j.name = n.has("name") ? n.child("name").string() : link.name;
  j.body0 = linkBody;
  j.body1 = parentBody;
  const Node typeNode = n.at("type");
  const std::string type = typeNode.string();
  if (type == "revolute" || type == "prismatic") {
    j.type = type == "revolute" ? JointType::Hinge : JointType::Slider;
    j.axis = n.at("axis").unitVec3();
    parseJointLimitsAndMotor(n, j);
  } else if (type == "spherical" || type == "fixed") {
    j.type = type == "spherical" ? JointType::Ball : JointType::Fixed;
    n.forbid("axis", "a " + type + " joint has no axis");
    const std::string why = "a " + type +
                            " joint takes no limits or motor (ODE's ball joint and Bullet's "
                            "point-to-point have none)";
    n.forbid("limits", why);
    n.forbid("motor", why);
  } else {
    typeNode.fail("unknown joint type " + inQuotes(type) +
                  " (known: revolute, prismatic, spherical, fixed)");
  }
  const bool anchorRequired = j.type == JointType::Hinge || j.type == JointType::Ball;
  j.anchor = anchorRequired || n.has("anchor") ? n.at("anchor").vec3() : link.position;
  return j;
}

// A base or link body: the role's fields, its name, and its inertia (given or from the shape).
Body parseArticulatedBody(const Node& n, BodyRole role, const std::string& name,
                          const Scene& scene) {
  Body b = parseBody(n, role, scene);
  b.name = name;
  if (scene.findBody(name) >= 0)
    n.fail("body name " + inQuotes(name) + " is already used by another body");
  if (n.has("inertia")) {
    if (role == BodyRole::FixedBase) n.child("inertia").fail("not allowed: a fixed base is static");
    b.inertia = n.child("inertia").positiveVec3();
  } else {
    b.inertia = inertiaOf(b.shape, b.mass);
  }
  return b;
}

void parseArticulation(const Node& n, Scene& scene) {
  n.allowOnly({"name", "fixed_base", "base", "links"});
  Articulation a;
  a.name = n.at("name").string();
  a.fixedBase = n.has("fixed_base") && n.child("fixed_base").boolean();
  const Node base = n.at("base");
  base.requireObject();
  base.forbid("name", "the base is named by the articulation's \"name\"");
  base.forbid("parent", "the base has no parent");
  base.forbid("joint", "the base has no joint (\"fixed_base\": true holds it to the world)");
  const BodyRole baseRole = a.fixedBase ? BodyRole::FixedBase : BodyRole::Link;
  const Body baseBody = parseArticulatedBody(base, baseRole, a.name, scene);

  const Node links = n.at("links");
  const std::size_t count = links.arraySize();
  if (count < 1 || count > std::size_t(kMaxLinks))
    links.fail("expected 1 to " + std::to_string(kMaxLinks) + " links, got " +
               std::to_string(count));
  std::vector<std::string> names;
  for (std::size_t k = 0; k < count; ++k) {
    names.push_back(links.item(k).at("name").string());
    if (names.back() == a.name || std::count(names.begin(), names.end(), names.back()) > 1)
      links.item(k).child("name").fail("link name " + inQuotes(names.back()) +
                                       " is used twice in articulation " + inQuotes(a.name));
  }
  std::vector<int> parent;
  for (std::size_t k = 0; k < count; ++k)
    parent.push_back(parentIndex(links.item(k), k, names, a.name));
  const std::vector<int> order = parentFirst(parent, links, names);

  a.base = int(scene.bodies.size());
  scene.bodies.push_back(baseBody);
  std::vector<int> slot(count, -1);  // file index -> index into a.links
  for (int k : order) {
    const Node link = links.item(std::size_t(k));
    Body body = parseArticulatedBody(link, BodyRole::Link, names[k], scene);
    ArticulatedLink l;
    l.body = int(scene.bodies.size());
    l.parent = parent[k] < 0 ? -1 : slot[parent[k]];
    const int parentBody = l.parent < 0 ? (a.fixedBase ? -1 : a.base) : a.links[l.parent].body;
    scene.bodies.push_back(std::move(body));
    l.joint = int(scene.joints.size());
    scene.joints.push_back(
        parseLinkJoint(link.at("joint"), scene.bodies[l.body], l.body, parentBody));
    slot[k] = int(a.links.size());
    a.links.push_back(l);
  }
  scene.articulations.push_back(std::move(a));
}

}  // namespace

void parseArticulations(const Node& list, Scene& scene) {
  for (std::size_t i = 0; i < list.arraySize(); ++i) {
    const Node entry = list.item(i);
    entry.requireObject();
    parseArticulation(entry, scene);
    if (scene.bodies.size() > std::size_t(limits::kMaxBodies))
      entry.fail("the scene has more than " + std::to_string(limits::kMaxBodies) + " bodies");
  }
}

void checkArticulationsAlone(const Node& joints, const Scene& scene, std::size_t first) {
  std::vector<int> owner(scene.bodies.size(), -1);
  for (std::size_t a = 0; a < scene.articulations.size(); ++a) {
    owner[scene.articulations[a].base] = int(a);
    for (const ArticulatedLink& l : scene.articulations[a].links) owner[l.body] = int(a);
  }
  for (std::size_t i = first; i < scene.joints.size(); ++i) {
    const Joint& j = scene.joints[i];
    for (int body : {j.body0, j.body1}) {
      if (body < 0 || owner[body] < 0) continue;
      joints.item(i - first).child("bodies").fail(
          "body " + inQuotes(scene.bodies[body].name) + " belongs to articulation " +
          inQuotes(scene.articulations[owner[body]].name) +
          ": only its own link joints may hold it (no loops)");
    }
  }
}

}  // namespace mlcp::scene::parse

namespace mlcp::scene {

std::vector<std::pair<int, int>> Scene::fixedBaseNeighbours() const {
  std::vector<std::pair<int, int>> pairs;
  for (const Articulation& a : articulations)
    if (a.fixedBase)
      for (const ArticulatedLink& l : a.links)
        if (l.parent < 0) pairs.emplace_back(l.body, a.base);
  return pairs;
}

}  // namespace mlcp::scene
