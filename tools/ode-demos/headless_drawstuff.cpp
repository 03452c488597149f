// A headless stand-in for ODE's drawstuff library, linked into each of ODE's own demos instead of
// the OpenGL one. dsSimulationLoop calls start(), then step(0) once a frame for the frame count
// (`--frames N` on the demo's command line, else the environment's ODE_DEMO_FRAMES, else 600),
// then stop(); every drawing and view call does nothing. dsElapsedTime reports one 60 Hz frame so
// demos that step by elapsed time step the same amount every frame. A key script
// (ODE_DEMO_KEYS="frame:key ...", e.g. "1:b 30:s") calls the demo's command() at those frames,
// for demos whose scene is built by key presses. dsStop ends the loop after the current frame.
#include <drawstuff/drawstuff.h>

#include <cstdarg>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "step_shim.hpp"

namespace {
bool stopRequested = false;

int frameCount(int argc, char** argv) {
  for (int i = 1; i + 1 < argc; ++i)
    if (std::strcmp(argv[i], "--frames") == 0) return std::atoi(argv[i + 1]);
  if (const char* env = std::getenv("ODE_DEMO_FRAMES")) return std::atoi(env);
  return 600;
}

// "frame:key frame:key ..." -> (frame, key) pairs.
std::vector<std::pair<int, int>> keyScript() {
  std::vector<std::pair<int, int>> keys;
  const char* env = std::getenv("ODE_DEMO_KEYS");
  if (!env) return keys;
  std::istringstream in(env);
  std::string item;
  while (in >> item) {
    auto colon = item.find(':');
    if (colon == std::string::npos || colon + 1 >= item.size()) {
      std::fprintf(stderr, "ODE_DEMO_KEYS: '%s' is not frame:key\n", item.c_str());
      std::exit(2);
    }
    keys.emplace_back(std::atoi(item.substr(0, colon).c_str()), item[colon + 1]);
  }
  return keys;
}
}  // namespace

extern "C" {

void dsSimulationLoop(int argc, char** argv, int, int, dsFunctions* fn) {
  const int frames = frameCount(argc, argv);
  const auto keys = keyScript();
  if (fn->start) fn->start();
  int frame = 0;
  for (; frame < frames && !stopRequested; ++frame) {
    for (const auto& [at, key] : keys)
      if (at == frame && fn->command) fn->command(key);
    odeDemoShimFrame(frame);
    if (fn->step) fn->step(0);
  }
  if (fn->stop) fn->stop();
  odeDemoShimFinish(frame);
}

static void report(const char* what, const char* msg, va_list ap) {
  std::fprintf(stderr, "drawstuff %s: ", what);
  std::vfprintf(stderr, msg, ap);
  std::fprintf(stderr, "\n");
}
void dsError(const char* msg, ...) {
  va_list ap;
  va_start(ap, msg);
  report("error", msg, ap);
  va_end(ap);
  std::exit(1);
}
void dsDebug(const char* msg, ...) {
  va_list ap;
  va_start(ap, msg);
  report("debug", msg, ap);
  va_end(ap);
  std::abort();
}
void dsPrint(const char*, ...) {}
void dsStop() { stopRequested = true; }
double dsElapsedTime() { return 1.0 / 60.0; }

// The view is kept (drawstuff's default until a demo sets one): demos steer cameras from it.
static float viewXyz[3] = {2, 0, 1}, viewHpr[3] = {180, 0, 0};
void dsSetViewpoint(float* xyz, float* hpr) {
  for (int i = 0; i < 3; ++i) {
    if (xyz) viewXyz[i] = xyz[i];
    if (hpr) viewHpr[i] = hpr[i];
  }
}
void dsGetViewpoint(float xyz[3], float hpr[3]) {
  for (int i = 0; i < 3; ++i) {
    xyz[i] = viewXyz[i];
    hpr[i] = viewHpr[i];
  }
}
void dsSetTexture(int) {}
void dsSetColor(float, float, float) {}
void dsSetColorAlpha(float, float, float, float) {}
void dsSetSphereQuality(int) {}
void dsSetCapsuleQuality(int) {}
void dsSetDrawMode(int) {}

void dsDrawBox(const float*, const float*, const float*) {}
void dsDrawSphere(const float*, const float*, float) {}
void dsDrawTriangle(const float*, const float*, const float*, const float*, const float*, int) {}
void dsDrawTriangles(const float*, const float*, const float*, int, int) {}
void dsDrawCylinder(const float*, const float*, float, float) {}
void dsDrawCapsule(const float*, const float*, float, float) {}
void dsDrawLine(const float*, const float*) {}
void dsDrawConvex(const float*, const float*, const float*, unsigned int, const float*,
                  unsigned int, const unsigned int*) {}

void dsDrawBoxD(const double*, const double*, const double*) {}
void dsDrawSphereD(const double*, const double*, const float) {}
void dsDrawTriangleD(const double*, const double*, const double*, const double*, const double*,
                     int) {}
void dsDrawTrianglesD(const double*, const double*, const double*, int, int) {}
void dsDrawCylinderD(const double*, const double*, float, float) {}
void dsDrawCapsuleD(const double*, const double*, float, float) {}
void dsDrawLineD(const double*, const double*) {}
void dsDrawConvexD(const double*, const double*, const double*, unsigned int, const double*,
                   unsigned int, const unsigned int*) {}
}
