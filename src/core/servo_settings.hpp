#pragma once
// The wall servo's settings, one source for the engine and the run configuration's defaults.

namespace grainlab {

// Stiffness-based proportional-integral wall servo. The error (sigma_target - sigma) times the wall
// area over the summed Kn of the wall's contacts is the displacement u that would cancel the error
// if only those contacts deformed (the PFC / YADE TriaxialStressController scaling, which keeps the
// loop stable whatever the stiffness). Each step the wall moves by gain*u plus an integral term that
// accumulates gain*u/integralSteps: a proportional servo alone lags a wall that must keep moving
// (a dilating sample under a constant sigma3) by an error proportional to its speed; the integral
// term learns that speed and removes the lag. Speed is capped; a wall with no contact approaches at
// the cap.
struct ServoSettings {
  double gain = 0.8;              // [-], fraction of u per step
  double integralSteps = 100.0;   // [steps]; 0 disables the integral term
  double maxSpeed = 0.5;          // [m/s]
};

}  // namespace grainlab
