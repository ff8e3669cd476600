// The header rules of spec/conus-format.md (V2..V7, V12..V15) on a HeaderModel, and the
// in-memory validator that runs them on the header a ConusFile would be written with.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>
#include <string>

#include "conus/core/camera.h"
#include "conus/core/color.h"
#include "conus/core/map_rules.h"
#include "header_model_pvt.h"

namespace conus::format {
namespace detail {
namespace {

std::string boxStr(const Box& b) {
    std::string s(1, '(');
    s += std::to_string(b.minX) + ", " + std::to_string(b.minY) + ") - (" + std::to_string(b.maxX) + ", " +
         std::to_string(b.maxY) + ")";
    return s;
}

const char* typeName(ChannelType t) {
    switch (t) {
        case ChannelType::Uint: return "UINT";
        case ChannelType::Half: return "HALF";
        case ChannelType::Float: return "FLOAT";
    }
    return "?";
}

// "present with the right type" or a message for `rule`; returns whether the value can be used.
template <class T>
bool need(const Attr<T>& a, const char* name, const char* expected, Rule rule, ValidationReport& r) {
    if (!a.present) {
        r.add(rule, std::string("missing attribute ") + name + " (" + expected + ")");
        return false;
    }
    if (!a.typeOk) {
        r.add(rule, std::string("attribute ") + name + " has type " + a.typeName + ", expected " + expected);
        return false;
    }
    return true;
}

// The same for a known attribute, named, typed and ruled by its row in kAttributes.
template <class T>
bool need(const HeaderModel& m, AttrMember<T> member, ValidationReport& r) {
    const AttributeSpec& spec = specOf(member);
    return need(m.*member, spec.name, spec.typeName(), spec.rule, r);
}

template <class T>
bool optional(const HeaderModel& m, AttrMember<T> member, ValidationReport& r) {
    return (m.*member).present && need(m, member, r);
}

void checkVersion(const HeaderModel& m, const PartModel& part, ValidationReport& r) {
    if (const int n = m.slot(PartKind::Conus).count; n > 1) r.add(Rule::V2, std::to_string(n) + " parts are named `" + m.partName(PartKind::Conus) + "`; exactly one is allowed");
    if (part.type != "scanlineimage" && part.type != "tiledimage") {
        r.add(Rule::V2, "part `" + part.name + "` has type `" + part.type + "`, expected scanlineimage or tiledimage");
    }
    if (part.type == "tiledimage" &&
        (part.tileWidth < 1 || part.tileHeight < 1 || part.tileWidth * part.tileHeight > kMaxTilePixels)) {
        r.add(Rule::V2, "part `" + part.name + "` has tiles of " + std::to_string(part.tileWidth) + "x" + std::to_string(part.tileHeight) +
                     " pixels; at most " + std::to_string(kMaxTilePixels) + " pixels a tile are read");
    }
    if (!need(m, &HeaderModel::version, r)) return;
    if (m.version.value > kFormatVersion) {
        r.add(Rule::V2, "written by a newer CoNUS (version " + std::to_string(m.version.value) + "); this reader knows version " +
                     std::to_string(kFormatVersion));
    } else if (m.version.value < 1) {
        r.add(Rule::V2, "invalid " + std::string(kAttrVersion) + " " + std::to_string(m.version.value));
    }
}

void checkChannels(const PartModel& part, const Limits& limits, ValidationReport& r, HeaderCheck& hc) {
    const auto n = static_cast<std::int64_t>(part.channels.size());
    if (n < 1 || n > kMaxChannels) {
        r.add(Rule::V3, "part `" + part.name + "` has " + std::to_string(n) + " channels; 1 to " + std::to_string(kMaxChannels) + " allowed");
    } else if (n > limits.maxChannels) {
        r.add(Rule::V3, "part `" + part.name + "` has " + std::to_string(n) + " channels, beyond the reader's limit of " +
                     std::to_string(limits.maxChannels));
        hc.limitExceeded = true;
    }
    std::set<std::string> seen;
    for (const ChannelModel& c : part.channels) {
        if (c.name.empty() || !seen.insert(c.name).second) r.add(Rule::V3, "channel name `" + c.name + "` is empty or repeated");
        if (c.type == ChannelType::Uint) r.add(Rule::V3, "channel `" + c.name + "` is UINT; HALF or FLOAT expected");
        if (c.xSampling != 1 || c.ySampling != 1) {
            r.add(Rule::V3, "channel `" + c.name + "` has sampling " + std::to_string(c.xSampling) + "x" +
                         std::to_string(c.ySampling) + "; 1x1 expected");
        }
        if (c.name == "Z" && c.type != ChannelType::Float) r.add(Rule::V3, std::string("channel `Z` is ") + typeName(c.type) + "; FLOAT expected");
    }
}

void checkWindows(const PartModel& part, const Limits& limits, ValidationReport& r, HeaderCheck& hc) {
    const Box& dw = part.dataWindow;
    if (!(dw == part.displayWindow) || dw.minX != 0 || dw.minY != 0) {
        r.add(Rule::V4, "part `" + part.name + "` dataWindow " + boxStr(dw) + " must equal displayWindow " + boxStr(part.displayWindow) +
                     " with origin (0, 0)");
    }
    const std::int64_t w = dw.width(), h = dw.height();
    if (w < 1 || h < 1 || w > kMaxImageSide || h > kMaxImageSide) {
        r.add(Rule::V4, "image size " + std::to_string(w) + "x" + std::to_string(h) + " outside [1, " + std::to_string(kMaxImageSide) + "]");
    } else if (w * h > limits.maxPixels) {
        r.add(Rule::V4, "image of " + std::to_string(w) + "x" + std::to_string(h) + " = " + std::to_string(w * h) +
                     " pixels exceeds the reader's limit of " + std::to_string(limits.maxPixels));
        hc.limitExceeded = true;
    }
}

void checkSourceAndKind(const HeaderModel& m, ValidationReport& r) {
    if (need(m, &HeaderModel::sourceSize, r)) {
        const auto [sw, sh] = m.sourceSize.value;
        if (sw < 1 || sh < 1 || sw > kMaxImageSide || sh > kMaxImageSide) {
            r.add(Rule::V5, "source size " + std::to_string(sw) + "x" + std::to_string(sh) + " outside [1, " +
                         std::to_string(kMaxImageSide) + "]");
        }
    }
    if (need(m, &HeaderModel::dataKind, r) && !tryParseEnum<DataKind>(m.dataKind.value)) {
        r.add(Rule::V6, "data kind `" + m.dataKind.value + "` is not one of " + enumChoices<DataKind>());
    }
}

void checkMapPart(const HeaderModel& m, const Limits& limits, ValidationReport& r, HeaderCheck& hc) {
    const PartSlot& slot = m.slot(PartKind::SamplingMap);
    if (slot.count != 1) {
        r.add(Rule::V7, std::to_string(slot.count) + " parts are named `" + m.partName(PartKind::SamplingMap) + "`; exactly one is required");
        if (slot.index < 0) return;
    }
    const PartModel& p = m.part(PartKind::SamplingMap);
    if (p.type != "scanlineimage") r.add(Rule::V7, "part `" + p.name + "` has type `" + p.type + "`, expected scanlineimage");
    const bool channelsOk = p.channels.size() == 2 && p.channels[0].name == kMapChannelU && p.channels[1].name == kMapChannelV &&
                            std::all_of(p.channels.begin(), p.channels.end(), [](const ChannelModel& c) {
                                return c.type == ChannelType::Float && c.xSampling == 1 && c.ySampling == 1;
                            });
    if (!channelsOk) {
        std::string list;
        for (const ChannelModel& c : p.channels) list += (list.empty() ? "" : ", ") + c.name + ":" + typeName(c.type);
        r.add(Rule::V7, "part `" + p.name + "` has channels {" + list + "}; exactly FLOAT `ud` and `vd` expected");
    }
    const Box& dw = p.dataWindow;
    const std::int64_t n = dw.width(), rows = dw.height();
    if (dw.minX != 0 || dw.minY != 0 || n < kMinMapSide || rows < kMinMapSide || n > kMaxMapSide || rows > kMaxMapSide) {
        r.add(Rule::V7, "part `" + p.name + "` dataWindow " + boxStr(dw) + " must be (0, 0) - (columns-1, rows-1) with columns and rows in [" +
                     std::to_string(kMinMapSide) + ", " + std::to_string(kMaxMapSide) + "]");
    } else if (n > limits.maxMapSide || rows > limits.maxMapSide) {
        r.add(Rule::V7, "sampling map of " + std::to_string(n) + "x" + std::to_string(rows) + " nodes exceeds the reader's limit of " +
                     std::to_string(limits.maxMapSide) + " a side");
        hc.limitExceeded = true;
    } else if (const Box& image = m.part(PartKind::Conus).dataWindow;
               image.width() >= 1 && image.height() >= 1 &&
               std::max(n, rows) > map_rules::maxSideForImage(image.width(), image.height())) {
        // Checked before the map's pixels are read: a 16x16 image may not make a reader hold 4097^2 nodes.
        r.add(Rule::V7, "sampling map of " + std::to_string(n) + "x" + std::to_string(rows) + " nodes is finer than its " +
                     std::to_string(image.width()) + "x" + std::to_string(image.height()) + " image can show; readers take at most " +
                     std::to_string(map_rules::maxSideForImage(image.width(), image.height())) + " nodes a side (limit mapNodesPerPixel)");
        hc.limitExceeded = true;
    }
}

// "0 (density), 1 (log), 2 (logr)": the falloff shapes as the file numbers them.
std::string shapeNumbers() {
    std::string list;
    for (const auto& [shape, name] : kEnumNameTable<FociFalloffShape>.names)
        list.append(list.empty() ? "" : ", ").append(std::to_string(static_cast<int>(shape))).append(" (").append(name).append(")");
    return list;
}

// A foci map's transition: both falloff scalars or neither, the width in (1, kMaxFalloffWidth], the
// shape one of the integers 0 .. kFalloffShapes - 1 (spec: Analytic-map parameters).
void checkFalloffParams(const HeaderModel& m, ValidationReport& r) {
    const auto width = m.params.find("falloffWidth"), shape = m.params.find("falloffShape");
    const std::string prefix = specOf(&HeaderModel::params).name;
    if ((width == m.params.end()) != (shape == m.params.end())) {
        r.add(Rule::V12, prefix + "falloffWidth and " + prefix + "falloffShape come together; this part has only one");
        return;
    }
    if (width == m.params.end()) return;
    const double w = width->second.value, s = shape->second.value;
    if (!(w > 1.0 && w <= map_rules::kMaxFalloffWidth)) {
        r.add(Rule::V12, prefix + "falloffWidth = " + numberText(w, 9) + " is not in (1, " +
                             numberText(map_rules::kMaxFalloffWidth, 9) + "]");
    }
    if (!(s >= 0 && s < map_rules::kFalloffShapes && s == std::floor(s))) {
        r.add(Rule::V12, prefix + "falloffShape = " + numberText(s, 9) + " is not one of " + shapeNumbers());
    }
}

// A ground map's row profile: v_d at K + 1 evenly spaced rows, from 0 to 1, strictly increasing.
void checkGroundRows(const HeaderModel& m, const std::string& kind, ValidationReport& r) {
    if (!m.groundRows.present) return;
    if (!need(m, &HeaderModel::groundRows, r)) return;
    const std::vector<float>& rows = m.groundRows.value;
    if (kind != "ground") {
        r.add(Rule::V12, std::string(kAttrGroundRows) + " belongs to a ground map, not to `" + kind + "`");
        return;
    }
    if (rows.size() < 2 || rows.size() > std::size_t(map_rules::kMaxGroundRows)) {
        r.add(Rule::V12, std::string(kAttrGroundRows) + " has " + std::to_string(rows.size()) + " values; 2 to " +
                             std::to_string(map_rules::kMaxGroundRows));
        return;
    }
    if (rows.front() != 0.0f || rows.back() != 1.0f)
        r.add(Rule::V12, std::string(kAttrGroundRows) + " runs from " + numberText(rows.front(), 9) + " to " +
                             numberText(rows.back(), 9) + ", not from 0 to 1");
    for (std::size_t k = 1; k < rows.size(); ++k)
        if (!(rows[k] > rows[k - 1])) {  // NaN fails too
            r.add(Rule::V12, std::string(kAttrGroundRows) + " is not strictly increasing at value " + std::to_string(k));
            break;
        }
}

void checkAnalytic(const HeaderModel& m, ValidationReport& r) {
    if (!m.mapKind.present) {
        if (m.foci.present || m.composition.present || m.groundRows.present || !m.params.empty()) {
            r.add(Rule::V12, std::string("analytic map parameters without ") + kAttrMapKind);
        }
        return;
    }
    if (!need(m, &HeaderModel::mapKind, r)) return;
    const std::string& kind = m.mapKind.value;
    if (kind == enumName(MapKind::Foci)) {
        if (need(m, &HeaderModel::foci, r)) {
            const std::vector<float>& f = m.foci.value;
            if (f.empty() || f.size() % 4 != 0) {
                r.add(Rule::V12, std::string(kAttrFoci) + " has " + std::to_string(f.size()) + " values; 4 per focus (u,v,r,k), at least one focus");
            } else {
                for (std::size_t i = 0; i < f.size() / 4; ++i) {
                    const float u = f[4 * i], v = f[4 * i + 1], rad = f[4 * i + 2], k = f[4 * i + 3];
                    if (!map_rules::isValidFocus(u, v, rad, k)) {
                        r.add(Rule::V12, "focus " + std::to_string(i) + " (u,v,r,k) = (" + numberText(u, 9) + ", " + numberText(v, 9) + ", " + numberText(rad, 9) + ", " +
                                      numberText(k, 9) + "): need u,v in [0,1], r in (0," + numberText(map_rules::kMaxFocusRadius, 9) + "], k in [1," +
                                      numberText(map_rules::kMaxMagnification, 9) + "]");
                    }
                }
            }
        }
        if (need(m, &HeaderModel::composition, r) && !tryParseEnum<FociComposition>(m.composition.value)) {
            r.add(Rule::V12, "composition `" + m.composition.value + "` is not one of " + enumChoices<FociComposition>());
        }
        checkFalloffParams(m, r);
        // The pictures' width / height a map file's foci were made for (spec: Analytic-map parameters).
        if (const auto aspect = m.params.find("aspect");
            aspect != m.params.end() && !(aspect->second.value >= 1.0 / 64 && aspect->second.value <= 64))
            r.add(Rule::V12, std::string(specOf(&HeaderModel::params).name) + "aspect = " + numberText(aspect->second.value, 9) +
                                 " is not a width / height in [1/64, 64]");
    } else if (!tryParseEnum<MapKind>(kind)) {
        r.add(Rule::V12, "map kind `" + kind + "` is not one of " + enumChoices<MapKind>());
    }
    checkGroundRows(m, kind, r);
    const AttributeSpec& params = specOf(&HeaderModel::params);
    for (const auto& [name, a] : m.params) {
        const std::string full = params.name + name;
        if (need(a, full.c_str(), params.typeName(), params.rule, r) && !std::isfinite(a.value)) {
            r.add(params.rule, full + " = " + numberText(a.value, 9) + " is not finite");
        }
    }
}

void checkCamera(const HeaderModel& m, ValidationReport& r) {
    if (!m.worldToCamera.present && !m.worldToNDC.present && !m.projection.present) return;
    for (const AttrMember<std::array<float, 16>> matrix : {&HeaderModel::worldToCamera, &HeaderModel::worldToNDC}) {
        const std::array<float, 16>& value = (m.*matrix).value;
        if (need(m, matrix, r) && !std::all_of(value.begin(), value.end(), [](float x) { return std::isfinite(x); })) {
            r.add(Rule::V13, std::string(specOf(matrix).name) + " has a non-finite element");
        }
    }
    if (need(m, &HeaderModel::projection, r) && !tryParseEnum<Projection>(m.projection.value)) {
        r.add(Rule::V13, "projection `" + m.projection.value + "` is not one of " + enumChoices<Projection>());
    } else if (!r.violates(Rule::V13)) {
        const CameraCheck check = describeCamera(CameraAttributes{m.projection.value, m.worldToCamera.value, m.worldToNDC.value});
        if (!check.problem.empty()) r.add(Rule::V13, check.problem);
    }
}

void checkDepth(const HeaderModel& m, const PartModel& part, ValidationReport& r) {
    std::string kind = "none";  // absent means no depth
    if (optional(m, &HeaderModel::depthKind, r)) {
        kind = m.depthKind.value;
        if (!tryParseEnum<DepthKind>(kind)) {
            r.add(Rule::V14, "depth kind `" + kind + "` is not one of " + enumChoices<DepthKind>());
            return;
        }
    }
    const bool hasZ = std::any_of(part.channels.begin(), part.channels.end(), [](const ChannelModel& c) { return c.name == "Z"; });
    if (hasZ && kind == "none") r.add(Rule::V14, "a `Z` channel needs conus:depthKind cameraDepth or height, not none");
    if (!hasZ && kind != "none") r.add(Rule::V14, "conus:depthKind is " + kind + " but there is no `Z` channel");
    if (kind != "none" && need(m, &HeaderModel::depthRange, r)) {
        const auto [nearV, farV] = m.depthRange.value;
        if (!(std::isfinite(nearV) && std::isfinite(farV) && nearV < farV)) {
            r.add(Rule::V14, "depth range (" + numberText(nearV, 9) + ", " + numberText(farV, 9) + ") must be finite with near < far");
        }
    }
    optional(m, &HeaderModel::depthUnits, r);
}

// V17: a depth image's Z means something only through its camera (cameraDepth along its axis).
void checkDepthImage(const HeaderModel& m, ValidationReport& r) {
    if (!m.dataKind.present || m.dataKind.value != enumName(DataKind::DepthImage)) return;
    std::string missing;
    if (!m.worldToCamera.present) missing += kAttrWorldToCamera;
    if (!m.worldToNDC.present) missing += std::string(missing.empty() ? "" : ", ") + kAttrWorldToNDC;
    if (!m.projection.present) missing += std::string(missing.empty() ? "" : ", ") + kAttrProjection;
    if (!missing.empty()) r.add(Rule::V17, "a depth image needs its camera; missing " + missing);
    const std::string kind = m.depthKind.present ? m.depthKind.value : enumName(DepthKind::None);
    if (kind != enumName(DepthKind::CameraDepth))
        r.add(Rule::V17, "a depth image's conus:depthKind is " + kind + ", not " + enumName(DepthKind::CameraDepth));
}

void checkColour(const HeaderModel& m, ValidationReport& r) {
    if (optional(m, &HeaderModel::sourceTransfer, r) && !tryParseEnum<Transfer>(m.sourceTransfer.value))
        r.add(Rule::V16, "source transfer `" + m.sourceTransfer.value + "` is not one of " + enumChoices<Transfer>());
    if (optional(m, &HeaderModel::sourceSampleType, r) && !tryParseEnum<SampleType>(m.sourceSampleType.value))
        r.add(Rule::V16, "source sample type `" + m.sourceSampleType.value + "` is not one of " + enumChoices<SampleType>());
    if (optional(m, &HeaderModel::chromaticities, r) &&
        !std::all_of(m.chromaticities.value.begin(), m.chromaticities.value.end(), [](float x) { return std::isfinite(x); }))
        r.add(Rule::V16, "chromaticities hold a non-finite value");
    if (optional(m, &HeaderModel::iccProfile, r)) {
        const auto bytes = base64Decode(m.iccProfile.value);
        if (!bytes)
            r.add(Rule::V16, std::string(kAttrIccProfile) + " is not base64 text (" + std::to_string(m.iccProfile.value.size()) + " characters)");
        else if (const std::string why = iccProfileProblem(*bytes); !why.empty())
            r.add(Rule::V16, std::string(kAttrIccProfile) + " is not an ICC profile: " + why);
    }
}

void checkDisplayWindows(const HeaderModel& m, ValidationReport& r) {
    for (std::size_t i = 1; i < m.parts.size(); ++i) {
        if (!(m.parts[i].displayWindow == m.parts[0].displayWindow)) {
            r.add(Rule::V15, "part " + std::to_string(i) + " (`" + m.parts[i].name + "`) displayWindow " + boxStr(m.parts[i].displayWindow) +
                          " differs from part 0's " + boxStr(m.parts[0].displayWindow));
        }
    }
}

}  // namespace

HeaderCheck checkHeaderRules(const HeaderModel& m, const Limits& limits, ValidationReport& r) {
    HeaderCheck hc;
    if (m.slot(PartKind::Conus).index < 0) {
        r.add(Rule::V2, "not a CoNUS file: no part named `conus` among " + std::to_string(m.parts.size()) + " part(s)");
        hc.notConus = true;
        return hc;
    }
    const PartModel& part = m.part(PartKind::Conus);
    checkVersion(m, part, r);
    checkChannels(part, limits, r, hc);
    checkWindows(part, limits, r, hc);
    checkSourceAndKind(m, r);
    checkMapPart(m, limits, r, hc);
    checkAnalytic(m, r);
    checkCamera(m, r);
    checkDepth(m, part, r);
    checkDepthImage(m, r);
    checkColour(m, r);
    checkDisplayWindows(m, r);
    return hc;
}

}  // namespace detail

namespace detail {

void checkPixelsAndMap(const ConusFile& file, const std::string& prefix, ValidationReport& report) {
    // The in-memory image must hold what its header promises (V4 covers the pixel array).
    const Image& im = file.image;
    if (im.width >= 1 && im.height >= 1 &&
        im.pixels.size() != std::size_t(im.width) * std::size_t(im.height) * im.channels.size()) {
        report.add(Rule::V4, prefix + "image holds " + std::to_string(im.pixels.size()) + " values; " + std::to_string(im.width) +
                                 "x" + std::to_string(im.height) + "x" + std::to_string(im.channels.size()) + " expected");
    }
    const ValidationReport grid = validateGrid(file.map);
    // V7's shape was already reported from the header model; keep the grid's own messages otherwise.
    for (const Issue& issue : grid.issues) {
        if (issue.rule != Rule::V7 || !report.violates(Rule::V7)) report.add(issue.rule, prefix + issue.message, issue.count);
    }
}

}  // namespace detail

ValidationReport validateConusFile(const ConusFile& file) {
    ValidationReport report;
    const detail::HeaderModel model = detail::modelOf(file);
    detail::checkHeaderRules(model, Limits{}, report);
    detail::checkPixelsAndMap(file, "", report);
    return report;
}

}  // namespace conus::format
