// The 1-D elastic rod's continuum solution (problems/elastic_rod.cpp): d'Alembert's tip
// displacement under a step end load, for tests and the mechanisms scene.
#pragma once

namespace geomint {

// Tip displacement u(L, t) of a fixed–free rod (length L, wave speed c = √(E/ρ), axial stiffness
// EA) at rest at t = 0 when a constant end load F is switched on: the wave F/(EA) reflected at
// both ends makes it a triangle wave between 0 and 2FL/(EA) with period 4L/c.
double dalembert_tip_displacement(double t, double length, double wave_speed, double load,
                                  double axial_stiffness);

}  // namespace geomint
