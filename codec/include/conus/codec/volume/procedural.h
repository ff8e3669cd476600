// Procedural test volumes with known content: Marschner-Lobb (the standard test signal of volume
// reconstruction filters, S. Marschner and R. Lobb, "An evaluation of reconstruction filters for
// volume rendering", 1994) and a 3-D Shepp-Logan head phantom (the ten ellipsoids of the modified
// 3-D phantom, values added where they overlap, seen through a Gaussian point spread of one voxel
// so that its one-voxel skull does not alias against the grid). Both are sampled over [-1,1]^3 on
// an n^3 grid with spacing 2 / (n - 1); values lie in [0,1].
#pragma once

#include <string>

#include "conus/core/volume.h"

namespace conus::codec {

// Throws conus::Error(InvalidArgument) for n outside [2, 1024] or n^3 past kMaxVolumeVoxels (n <= 645).
Volume marschnerLobb(int n = 64);
Volume sheppLogan3d(int n = 64);

// "procedural:marschner-lobb[:n]" or "procedural:shepp-logan[:n]"; anything else throws
// InvalidArgument naming the forms.
Volume proceduralVolume(const std::string& spec);

}  // namespace conus::codec
