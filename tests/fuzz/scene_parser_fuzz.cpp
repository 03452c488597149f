// libFuzzer target: the scene parser (mlcp-scene/1) on any text. Invariant: a FormatError of one
// short line, or a scene within the limits of mlcp/scene/scene_limits.hpp (checked again here,
// and every body's inertia finite); anything else is a finding.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "fuzz_checks.hpp"
#include "mlcp/scene/scene.hpp"
#include "mlcp/scene/scene_limits.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  mlcp::scene::Scene scene;
  try {
    scene = mlcp::scene::parseScene(text, "fuzz.json");
  } catch (const mlcp::scene::FormatError& e) {
    mlcp::fuzz::checkMessage(e.what());
    return 0;
  }
  try {
    mlcp::scene::checkSceneLimits(scene);
  } catch (const mlcp::scene::FormatError& e) {
    mlcp::fuzz::violated("a parsed scene is outside the limits", e.what());
  }
  for (const mlcp::scene::Body& b : scene.bodies)
    for (double i : b.inertia)
      if (!std::isfinite(i) || i < 0) mlcp::fuzz::violated("inertia not finite", b.name);
  return 0;
}
