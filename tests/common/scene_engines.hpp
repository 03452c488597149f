// The engine loaders of this build by name ("bullet", "ode"), for the tests that run scene
// files in every engine (world_test, content_test). MLCP_HAVE_BULLET / MLCP_HAVE_ODE say which
// loaders the test is linked with. "bullet-multibody" is not among them: on scenes without
// articulated bodies it gives bullet's answers; articulation_test runs it.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/world.hpp"
#ifdef MLCP_HAVE_BULLET
#include "mlcp/bullet/scene_loader.hpp"
#endif
#ifdef MLCP_HAVE_ODE
#include "mlcp/ode/scene_loader.hpp"
#endif

namespace mlcp::test {

using SceneLoader =
    std::function<std::unique_ptr<scene::World>(const scene::Scene&, const scene::RunSettings&)>;

inline std::vector<std::pair<std::string, SceneLoader>> sceneEngines() {
  std::vector<std::pair<std::string, SceneLoader>> e;
#ifdef MLCP_HAVE_BULLET
  e.emplace_back("bullet", [](const scene::Scene& s, const scene::RunSettings& run) {
    return mlcp::bullet::loadWorld(s, run);
  });
#endif
#ifdef MLCP_HAVE_ODE
  e.emplace_back("ode", &mlcp::ode::loadWorld);
#endif
  return e;
}

// The loader of that engine ("bullet-multibody" too), or an empty function when this build has
// none.
inline SceneLoader sceneLoader(const std::string& engine) {
#ifdef MLCP_HAVE_BULLET
  if (engine == "bullet-multibody")
    return [](const scene::Scene& s, const scene::RunSettings& run) {
      return mlcp::bullet::loadWorld(s, run, mlcp::bullet::Coordinates::Reduced);
    };
#endif
  for (auto& [name, loader] : sceneEngines())
    if (name == engine) return loader;
  return {};
}

}  // namespace mlcp::test
