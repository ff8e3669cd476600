// Importance taken from the picture itself, for the automatic maps (auto_map.h): its detail or the
// faces found in it. The rules go by name ("detail", "faces") wherever a user picks one: `conus
// encode --importance`, `map auto`, `bake relief`, Python's conus.importance.
//
// Both rules read the picture as a display shows it (imageio::displayEncoded): detail is the
// detail people see, and the face detector was trained on ordinary 8-bit photographs.
#pragma once

#include "conus/core/enum_names.h"
#include "conus/core/image.h"

namespace conus::codec {

enum class ImportanceRule { Detail, Faces };
// Their names (core/enum_names.h: enumName, tryParseEnum, enumChoices), exact as the CLI's choices.
constexpr auto enumNameTable(ImportanceRule) {
    return makeEnumNameTable<ImportanceRule>("importance rule", {{ImportanceRule::Detail, "detail"}, {ImportanceRule::Faces, "faces"}});
}

// The importance `rule` gives the display-encoded picture `shown`: detailImportance or
// faceImportance.
Image ruleImportance(ImportanceRule rule, const Image& shown);

// Local detail of an image: gradient magnitude of its luminance (one channel "Y"), computed at
// most 1024 px a side.
Image detailImportance(const Image& image);
// The same of the shown picture's luminance alone (one channel: the mean of R, G and B, or the
// grey channel, as detailImportance takes it), which a caller may make a band of rows at a time
// without a display-encoded copy of the whole picture.
Image detailImportanceOfLuminance(const Image& luminance);
struct EightBitImage;  // image/encode.h
// The same of a picture kept as 8-bit codes, as a display shows it: each code's value
// `shownCode[code]` (nullptr: code / 255). With imageio::displayEncoded's value of each code's
// linear value, exactly detailImportance(imageio::displayEncoded(linearImage(codes))).
Image detailImportance(const EightBitImage& codes, const float* shownCode = nullptr);

// High on each face found in `shown` (a soft disc over every detection), zero elsewhere, at most
// 1024 px a side; throws conus::Error(Unsupported: it depends on the picture, exit 1) when no face
// is found or the detector's data is missing. The detector (OpenCV, faces.cpp) is the module
// libconus_faces in <libdir>/conus, loaded on the first call; a static build links it in.
Image faceImportance(const Image& shown);

// What the faces module (extern "C" conusFaceImportance) hands out.
using FaceImportanceFunction = Image (*)(const Image& shown);

}  // namespace conus::codec
