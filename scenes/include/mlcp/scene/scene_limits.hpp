// mlcp/scene/scene_limits.hpp: the ranges a scene may have, checked before any engine sees it.
//
// parseScene() ends with checkSceneLimits(): every number of the expanded scene (generators
// included, so a stack of a million metres fails as surely as one body there) must lie in the
// ranges below. They are wide for real scenes (a 0.1 mm bolt to a 10 km slab, a 100 g domino
// to a 100 000 t block) and keep what the engines compute finite: inertia m l^2 <= 1e16,
// momenta m v <= 1e12, contact depths and joint errors far from overflow. Beyond them, Bullet
// and ODE lose precision long before they fail, and ODE aborts on an assertion (dxNormalize3/4)
// once a velocity, an axis or a quaternion becomes non-finite. Directions (joint axes, plane
// normals) and quaternions are normalised by the parser and must come out unit length here.
//
// The same table is in scenes/README.md ("Limits"). Cost: one pass over the bodies and joints.
#pragma once

#include "mlcp/scene/scene.hpp"

namespace mlcp::scene::limits {

inline constexpr double kMinLength = 1e-4;     // m: box edges, radii (a capsule's length may be 0)
inline constexpr double kMaxLength = 1e4;      // m: box edges, radii, capsule lengths
inline constexpr double kMaxCoordinate = 1e5;  // m: |positions|, |anchors|, |plane offsets|
inline constexpr double kMinMass = 1e-4;       // kg, of a dynamic body (0 is static)
inline constexpr double kMaxMass = 1e8;        // kg
inline constexpr double kMaxInertia = 1e16;    // kg m^2: an articulated body's given "inertia"
inline constexpr double kMaxSpeed = 1e4;       // m/s: |velocity| components, |motor velocity|
inline constexpr double kMaxAngularSpeed = 1e4;  // rad/s: |angular velocity| components
inline constexpr double kMaxGravity = 1e4;       // m/s^2: |gravity| components
inline constexpr double kMaxFriction = 100;      // friction coefficient
inline constexpr double kMaxForce = 1e10;        // N or N m: motor max_force
inline constexpr double kMaxJointLimit = 1e5;    // rad or m: |limits.lower|, |limits.upper|
// rad or m: a six_dof axis limit; up to Bullet's SIMD_INFINITY (1e30), which stands for "none".
inline constexpr double kMaxDofLimit = 1e30;
inline constexpr double kMaxStiffness = 1e10;  // N/m or N m/rad: springs, suspensions (and damping)
inline constexpr double kMaxGearRatio = 1e4;   // |gear ratio|
inline constexpr double kMinTimeStep = 1e-6;   // s
inline constexpr double kMaxTimeStep = 1;      // s
inline constexpr double kMaxCfm = 1;           // settings.cfm
inline constexpr long long kMaxSteps = 10000000;
inline constexpr long long kMaxIterations = 1000000;
inline constexpr double kMinTolerance = 1e-16;  // solver.tolerance
inline constexpr double kMaxTolerance = 1;
inline constexpr long long kMaxBodies = 100000;  // after generators are expanded
inline constexpr long long kMaxJoints = 100000;
inline constexpr long long kMaxMaterials = 1000;
inline constexpr double kUnitTolerance = 1e-9;  // | |axis| - 1 |, | |q| - 1 | after parsing

}  // namespace mlcp::scene::limits

namespace mlcp::scene {

// Throws FormatError("<source>: <where>: <what is out of range>") for the first value of the
// scene outside the limits above, naming the body, joint or setting ("body \"box.3\": mass").
void checkSceneLimits(const Scene& scene);

}  // namespace mlcp::scene
