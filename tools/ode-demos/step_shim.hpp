// The step shim's hooks for the headless drawstuff (step_shim.cpp).
#pragma once

// Called before each frame's step(0) (frame counts from 0).
void odeDemoShimFrame(int frame);
// Called once after the loop: writes the run's record (ODE_DEMO_OUT) and prints its summary.
void odeDemoShimFinish(int frames);
