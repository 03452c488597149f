// mlcp/scene/joints.hpp: the joints of a scene (scene.hpp) and their limits, motors, springs.
//
// Anchors and axes are world-frame values at creation; a joint's angle or offset is 0 in the
// pose the bodies start in. The hinge angle is the rotation of body0 relative to body1 (or the
// world) about the axis, right-handed; the slider offset the displacement of body0 relative to
// body1 along the axis. The articulations of articulation.hpp use the same structs for their
// links' joints, so one limit or motor means the same in every engine.
#pragma once

#include <array>
#include <string>

#include "mlcp/scene/geometry.hpp"

namespace mlcp::scene {

enum class JointType { Ball, Hinge, Slider, Fixed, ConeTwist, SixDof, Universal, Hinge2, Gear };
// "ball", "hinge", "slider", "fixed", "cone_twist", "six_dof", "universal", "hinge2", "gear".
const char* toString(JointType type);

// Range of the hinge angle (rad) or the slider offset (m); lower <= upper. Hinge-2: the
// steering angle (rad) about `axis`.
struct JointLimits {
  bool enabled = false;
  double lower = 0, upper = 0;
};

// Velocity motor: drives the hinge angle (rad/s) or the slider offset (m/s) towards
// `velocity` with at most `maxForce` (N m for a hinge, N for a slider).
struct JointMotor {
  bool enabled = false;
  double velocity = 0;
  double maxForce = 0;
};

// A spring towards the pose at creation: force -stiffness x - damping dx/dt on the offset x
// (m; N/m and N s/m) or angle (rad; N m/rad and N m s/rad).
struct JointSpring {
  bool enabled = false;
  double stiffness = 0;
  double damping = 0;
};

// Cone-twist limits, rad: the twist about `axis` stays within +-twist, the swing of the twist
// axis within +-swing1 about `normal` and +-swing2 about axis x normal (Bullet's
// btConeTwistConstraint spans: an elliptic cone). All three in (0, pi); a twist of 0 locks it.
struct ConeLimits {
  double swing1 = 0, swing2 = 0, twist = 0;
};

// One axis of a six_dof joint: the offset (m) or angle (rad) of bodies[0] relative to
// bodies[1] (or the world) in the joint frame, as for the hinge and slider, either locked at 0,
// free, or kept in [lower, upper]; a spring may act on it in every mode but locked. Large limits
// (1e30, Bullet's SIMD_INFINITY style) are allowed and kept as written.
struct AxisDof {
  enum class Mode { Locked, Free, Limited };
  Mode mode = Mode::Locked;
  double lower = 0, upper = 0;
  JointSpring spring;
};

struct Joint {
  std::string name;
  JointType type = JointType::Ball;
  int body0 = -1;        // index into Scene::bodies, always a dynamic body
  int body1 = -1;        // index into Scene::bodies (a dynamic body), or -1 for the world
  Vec3 anchor{0, 0, 0};  // world frame at creation, m (all types; gear: bodies[0]'s centre)
  // Unit, world frame at creation: hinge, slider axis; cone_twist twist axis; six_dof frame x;
  // universal axis fixed in bodies[0]; hinge2 steering axis (fixed in bodies[0], the chassis);
  // gear bodies[0]'s axis of rotation.
  Vec3 axis{0, 0, 1};
  // Unit, world frame at creation: universal axis fixed in bodies[1]; hinge2 wheel axle (fixed
  // in bodies[1]); gear bodies[1]'s axis of rotation. Perpendicular to `axis` for universal and
  // hinge2.
  Vec3 axis2{0, 0, 1};
  // Unit, perpendicular to `axis`, world frame at creation: cone_twist swing1 axis, six_dof
  // frame y (frame z is axis x normal).
  Vec3 normal{0, 1, 0};
  Vec3 anchor2{0, 0, 0};  // gear: bodies[1]'s centre, world frame at creation, m
  JointLimits limits;     // hinge, slider, hinge2 (steering; default locked at 0)
  JointMotor motor;       // hinge, slider
  ConeLimits cone;        // cone_twist
  // six_dof: linear x, y, z then angular x, y, z of the joint frame (x = axis, y = normal).
  std::array<AxisDof, 6> dofs;
  JointSpring suspension;  // hinge2: along `axis` (default: rigid)
  // Gear: bodies[0] turns `ratio` times as fast as bodies[1], the other way round:
  // w0 . axis = -ratio w1 . axis2 (an external gear pair; ratio > 0).
  double ratio = 1;
  // Whether the two bodies still collide with each other. Default false.
  bool collideConnected = false;
};
}  // namespace mlcp::scene
