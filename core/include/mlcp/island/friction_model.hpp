// mlcp/island/friction_model.hpp: which friction model an island's contacts are solved with.
//
//   box   the engines' own model (the default): per contact a normal row and one or two tangent
//         rows whose bounds are -mu x_n .. mu x_n (findex). pgs and dantzig take it as it is; it
//         lets the friction force reach mu x_n sqrt(2) along a diagonal of the tangent frame, so
//         a body sliding diagonally feels up to 41% more friction than one sliding along a
//         tangent, and its slide turns toward the nearest diagonal.
//   cone  the polyhedral cone (Stewart-Trinkle / Anitescu-Potra, friction_cone.hpp): k
//         directions per contact, a standard LCP in k + 1 unknowns per contact whose friction
//         stays within mu x_n in every direction, exact along the k directions and at least
//         mu x_n cos(pi / k) between two (0.707 at k = 4, 0.924 at k = 8, 0.981 at k = 16).
//         Its lambda rows have zero diagonal entries and A is not symmetric (and, with the
//         redundant contacts of a resting face, singular in its friction block): lemke is the
//         method for it (auto's choice); dantzig takes it but, made for P-matrices, often stalls
//         and says so; newton takes it (any square A); pgs, gs and ldlt cannot take it at all
//         and are refused when the settings are made. Lemke needs a little cfm on the rows (the
//         engines' cfm / dt, 6e-4 at a world cfm of 1e-5, as the scenes set): at 1e-10..1e-8
//         (ODE's double-precision default world CFM is 1e-10) the four coplanar contacts of a
//         face make near-singular pivots, and a few percent of its solves end in a false ray
//         termination or a wrong basis; those answers are rejected and the box answers instead.
//
// RowSolver (row_solver.hpp) applies the setting per island: with "cone", an island with
// friction rows is solved as the cone's LCP (stage 3, RowSolver::solveCone) and mapped back to
// the engine's rows; its residual is the cone LCP's, recomputed by residual.hpp. An island the
// cone cannot express (friction_cone.hpp: rolling friction, anisotropic friction) keeps the box
// and says so in its message. The fallback, when the cone's answer is not acceptable, runs on
// the engine's box rows: the step then gets the engine's friction for that island rather than
// no answer.
#pragma once

#include <string>

namespace mlcp {

enum class FrictionModel { Box, Cone };

// "box" or "cone".
const char* toString(FrictionModel model);
// Parses "box" / "cone" into model; false (model unchanged) for anything else.
bool parseFrictionModel(const std::string& name, FrictionModel& model);

// The range of friction directions per contact the cone accepts. Below 3 the polygon encloses
// no area; above 64 its inscribed friction (cos(pi / 64) = 0.9988 mu) is within a thousandth of
// the circle while each contact costs 65 LCP unknowns (lemke's dense tableau grows with their
// square).
inline constexpr int kMinConeDirections = 3;
inline constexpr int kMaxConeDirections = 64;
// Default number of friction directions per contact: the engine's tangents +-t1, +-t2.
inline constexpr int kDefaultConeDirections = 4;

// Why these settings cannot run ("" when they can): directions outside [kMinConeDirections,
// kMaxConeDirections] (checked whatever the model, so that a later switch to the cone cannot
// fail), or the cone with a primary that cannot take its LCP (pgs, gs, ldlt).
std::string frictionSettingsError(FrictionModel model, int directions, const std::string& solver);

}  // namespace mlcp
