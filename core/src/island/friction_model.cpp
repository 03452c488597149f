#include "mlcp/island/friction_model.hpp"

namespace mlcp {

const char* toString(FrictionModel model) { return model == FrictionModel::Cone ? "cone" : "box"; }

bool parseFrictionModel(const std::string& name, FrictionModel& model) {
  if (name == "box") {
    model = FrictionModel::Box;
  } else if (name == "cone") {
    model = FrictionModel::Cone;
  } else {
    return false;
  }
  return true;
}

std::string frictionSettingsError(FrictionModel model, int directions, const std::string& solver) {
  if (directions < kMinConeDirections || directions > kMaxConeDirections)
    return "friction directions must be in [" + std::to_string(kMinConeDirections) + ", " +
           std::to_string(kMaxConeDirections) + "] (got " + std::to_string(directions) + ")";
  if (model != FrictionModel::Cone) return "";
  if (solver == "pgs")
    return "friction 'cone' is an LCP with zero diagonal entries (its lambda rows), which pgs "
           "cannot sweep; use lemke, dantzig or auto";
  if (solver == "gs" || solver == "ldlt")
    return "friction 'cone' is an LCP, which " + solver +
           " (equality rows only) cannot solve; use lemke, dantzig or auto";
  return "";
}

}  // namespace mlcp
