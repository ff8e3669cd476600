#include "conus/core/volume.h"

#include <algorithm>
#include <cmath>

#include "conus/core/error.h"

namespace conus {

void checkVolume(const Volume& volume, const std::string& what) {
    const auto sizeText = [&] {
        return std::to_string(volume.width) + "x" + std::to_string(volume.height) + "x" + std::to_string(volume.depth);
    };
    if (volume.width < 2 || volume.height < 2 || volume.depth < 2)
        throw Error(ErrorCode::InvalidArgument, what + ": size " + sizeText() + " has a side below 2");
    // Each side is an int: the product of three fits in 128 bits, not 64; compare step by step.
    const std::size_t plane = static_cast<std::size_t>(volume.width) * static_cast<std::size_t>(volume.height);
    if (volume.values.size() % plane != 0 || volume.values.size() / plane != static_cast<std::size_t>(volume.depth))
        throw Error(ErrorCode::InvalidArgument,
                    what + ": " + std::to_string(volume.values.size()) + " values for a " + sizeText() + " volume");
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(volume.spacing[a]) || volume.spacing[a] <= 0.0)
            throw Error(ErrorCode::InvalidArgument, what + ": spacing " + numberText(volume.spacing[a]) + " along axis " +
                                                        std::to_string(a) + " is not a positive number");
    const auto bad = std::find_if(volume.values.begin(), volume.values.end(), [](float v) { return !std::isfinite(v); });
    if (bad != volume.values.end()) {
        const std::size_t i = static_cast<std::size_t>(bad - volume.values.begin());
        throw Error(ErrorCode::Corrupt, what + ": sample (" + std::to_string(i % volume.width) + ", " +
                                            std::to_string(i % plane / volume.width) + ", " + std::to_string(i / plane) +
                                            ") is " + numberText(*bad) + "; every sample must be finite");
    }
}

}  // namespace conus
