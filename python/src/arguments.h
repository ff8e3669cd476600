// What Python users pass, converted with one-line messages: the arrays (pixels and data), foci,
// channel names, sizes, views and counts; and the arrays CoNUS hands back. Type mistakes raise
// TypeError, bad values conus.Error (invalid-argument), each naming the argument and what it should be.
//
// The rule for pixel arrays (docs/python.md): float arrays are linear light; uint8 and uint16
// arrays are display-encoded codes, converted as an 8- or 16-bit PNG is (sRGB to linear light,
// alpha associated); colorspace="linear" or "srgb" overrides either. Other dtypes are refused.
// NaN and infinite values are kept with a warning, or repaired as --fix-nonfinite does.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "conus/codec/builders/foci.h"
#include "conus/codec/image/decode.h"
#include "conus/core/enum_names.h"
#include "conus/core/error.h"
#include "conus/core/image.h"
#include "conus/imageio/image_file.h"

namespace conus::python {

namespace py = pybind11;

// Y; Y, A; R, G, B; R, G, B, A; else C0, C1, ...: the names of an array's channels when none are given.
std::vector<std::string> defaultChannelNames(int count);

// "the str 'photo.png'", "a tuple of 3", "an array of shape (4, 5)": what was given, for messages.
std::string describe(py::handle value);

// "'a', 'b' or 'c'": the names an argument accepts, for its one-line error.
std::string quotedChoices(const std::vector<std::string>& names);

// The value of E named `text` (core/enum_names.h), for the argument `argument`; else conus.Error
// "argument must be 'a', 'b' or 'c', not 'x'".
template <class E>
E enumArgument(const std::string& text, const char* argument) {
    if (const std::optional<E> value = tryParseEnum<E>(text)) return *value;
    throw Error(ErrorCode::InvalidArgument,
                std::string(argument) + " must be " + quotedChoices(enumNames<E>()) + ", not '" + text + "'");
}

// colorspace= "auto" (the rule above) or a display-referred Transfer (srgb, linear); fix_nonfinite=
// a NonFiniteRepair.
inline constexpr const char* kAutoColorspace = "auto";
struct PixelRules {
    std::string colorspace = kAutoColorspace;
    std::string fixNonFinite = enumName(imageio::NonFiniteRepair::Keep);
};

// A picture: (H, W) or (H, W, C) of linear light after the rule above.
Image pixelsFrom(py::handle pixels, const std::optional<std::vector<std::string>>& channels, const char* what,
                 const PixelRules& rules = {});
// Data (importance): values as they are; integer codes scaled to [0, 1] as an image file's are.
Image dataFrom(py::handle values, const char* what);

std::vector<codec::Focus> fociFrom(py::handle foci);
std::optional<std::vector<std::string>> channelsFrom(py::handle channels);
std::optional<std::pair<int, int>> sizeFrom(py::handle size, const char* what = "size");
codec::View viewFrom(py::handle view);
int iterationsFrom(py::handle fit);

// Real numbers only: numpy's cast would drop a complex array's imaginary part and turn an object
// array's items into numbers by any means they offer.
void requireReal(const py::array& input, const std::string& what);

// The image as an array that owns it: no copy of the pixels (a capsule holds the C++ image).
py::array toArray(Image image);

// Warns (a UserWarning) with `text` through conus._warn (python/conus/__init__.py): at the caller's
// line, naming the call; raises if warnings are errors.
void warn(const std::string& text);

}  // namespace conus::python
