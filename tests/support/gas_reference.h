// The gas integral by brute force, the oracle GasVolume::integrate is checked against (tests) and
// measured against (bench/gas_bench.cpp): every sphere tested along the ray (no BVH), the midpoint
// rule with `steps` steps per piece of constant membership, and exact visibility (a shadow ray
// through the opaque surfaces and the gas) at every step.
#pragma once
#include "render/gas.h"

namespace vr {

GasVolume::Result integrate_gas_reference(const GasVolume& gas, const Ray& ray, double t_end,
                                          const GasVolume::Lighting& lighting, int steps);

}  // namespace vr
