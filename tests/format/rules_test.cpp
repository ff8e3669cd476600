// Every rule V1..V17 of spec/conus-format.md, each broken once: in memory where a ConusFile can
// express the fault, else as a malformed file written with OpenEXR directly. (A reflection
// asset's V18 and V19: reflection_asset_test.cpp.)
#include <gtest/gtest.h>

#include <ImfChannelList.h>
#include <ImfFloatVectorAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIntAttribute.h>
#include <ImfMatrixAttribute.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>
#include <ImfVecAttribute.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>

#include "conus/core/limits.h"
#include "raw_file.h"
#include "test_files.h"

namespace conus::format {
namespace {

using testing::TempDir;
using testing::errorFrom;
using testing::validFile;
using testing::Mutate;
using testing::eraseAttribute;
using testing::writeRaw;

// The report is not ok and names only `rule`.
::testing::AssertionResult onlyRule(const ValidationReport& r, int rule) {
    if (r.ok()) return ::testing::AssertionFailure() << "report is ok, expected V" << rule;
    for (const Issue& i : r.issues) {
        if (number(i.rule) != rule) return ::testing::AssertionFailure() << "expected only V" << rule << ", got:\n" << r.str();
    }
    return ::testing::AssertionSuccess();
}

class RuleTest : public ::testing::Test {
protected:
    ValidationReport raw(const Mutate& mutate, bool withMap = true) {
        writeRaw(m_dir.file("raw.exr"), validFile(), mutate, withMap);
        return validateConusFile(m_dir.file("raw.exr"));
    }
    TempDir m_dir;
};

TEST_F(RuleTest, RawWriterMakesValidFiles) {
    const ValidationReport r = raw([](Imf::Header&, Imf::Header&) {});
    EXPECT_TRUE(r.ok()) << r.str();
    EXPECT_TRUE(validateConusFile(validFile()).ok()) << validateConusFile(validFile()).str();
}

TEST_F(RuleTest, UnknownConusAttributesAreIgnored) {
    EXPECT_TRUE(raw([](Imf::Header& c, Imf::Header&) { c.insert("conus:futureThing", Imf::IntAttribute(7)); }).ok());
}

TEST_F(RuleTest, V1NotAnExrFile) {
    std::ofstream(m_dir.file("junk.exr")) << "this is not an EXR file at all";
    const ValidationReport r = validateConusFile(m_dir.file("junk.exr"));
    EXPECT_TRUE(onlyRule(r, 1));
    std::ofstream(m_dir.file("empty.exr")).close();
    EXPECT_TRUE(onlyRule(validateConusFile(m_dir.file("empty.exr")), 1));
    const Error e = errorFrom([&] { readConusFile(m_dir.file("junk.exr")); });
    EXPECT_EQ(e.code(), ErrorCode::Corrupt);
}

TEST_F(RuleTest, V2NoConusPartIsNotConus) {
    const ValidationReport r = raw([](Imf::Header& c, Imf::Header&) { c.setName("other"); });
    EXPECT_TRUE(onlyRule(r, 2));
    const Error e = errorFrom([&] { readConusFile(m_dir.file("raw.exr")); });
    EXPECT_EQ(e.code(), ErrorCode::NotConus);
    EXPECT_NE(std::string(e.what()).find("not a CoNUS file"), std::string::npos) << e.what();
}

TEST_F(RuleTest, V2NewerVersionIsRefused) {
    const ValidationReport r = raw([](Imf::Header& c, Imf::Header&) { c.insert("conus:version", Imf::IntAttribute(2)); });
    EXPECT_TRUE(onlyRule(r, 2));
    EXPECT_NE(r.str().find("written by a newer CoNUS (version 2)"), std::string::npos) << r.str();
}

TEST_F(RuleTest, V2VersionMissingOrMistyped) {
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) { eraseAttribute(c, "conus:version"); }), 2));
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) {
                             eraseAttribute(c, "conus:version");
                             c.insert("conus:version", Imf::StringAttribute("1"));
                         }),
                         2));
}

TEST_F(RuleTest, V3Channels) {
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) { c.channels().insert("Q", Imf::Channel(Imf::UINT)); }), 3));
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) { c.channels().insert("S", Imf::Channel(Imf::HALF, 2, 2)); }), 3));
    // A HALF Z breaks V3 (Z is FLOAT); depthKind must then say what Z is, so set it too.
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) {
                             c.channels().insert("Z", Imf::Channel(Imf::HALF));
                             c.insert("conus:depthKind", Imf::StringAttribute("height"));
                             c.insert("conus:depthRange", Imf::V2fAttribute(Imath::V2f(0, 1)));
                         }),
                         3));
    ConusFile f = validFile();
    f.image = makeImage(2, 2, std::vector<std::string>(kMaxChannels + 1, "C"));
    for (int i = 0; i <= kMaxChannels; ++i) f.image.channels[i] = std::to_string(100 + i).insert(0, 1, 'C');
    EXPECT_TRUE(onlyRule(validateConusFile(f), 3));
    f = validFile();
    f.image.channels[1] = f.image.channels[0];
    EXPECT_TRUE(onlyRule(validateConusFile(f), 3));
}

TEST_F(RuleTest, V4Windows) {
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) { c.dataWindow() = Imath::Box2i({0, 0}, {6, 5}); }), 4));
    ConusFile f = validFile();
    f.image.width = 0;
    f.image.pixels.clear();
    EXPECT_TRUE(onlyRule(validateConusFile(f), 4));
    f = validFile();
    f.image.pixels.pop_back();
    EXPECT_TRUE(onlyRule(validateConusFile(f), 4));
}

TEST_F(RuleTest, V5SourceSize) {
    ConusFile f = validFile();
    f.sourceHeight = 70000;
    EXPECT_TRUE(onlyRule(validateConusFile(f), 5));
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) { eraseAttribute(c, "conus:sourceSize"); }), 5));
}

TEST_F(RuleTest, V6DataKind) {
    ConusFile f = validFile();
    f.dataKind = static_cast<DataKind>(42);
    EXPECT_TRUE(onlyRule(validateConusFile(f), 6));
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) { c.insert("conus:dataKind", Imf::StringAttribute("photo")); }), 6));
}

TEST_F(RuleTest, V7MapPart) {
    ConusFile f = validFile();
    f.map = testing::identityGrid(1, 4);
    EXPECT_TRUE(onlyRule(validateConusFile(f), 7));
    EXPECT_TRUE(onlyRule(raw([](Imf::Header&, Imf::Header&) {}, false), 7));
    EXPECT_TRUE(onlyRule(raw([](Imf::Header&, Imf::Header& m) { m.channels().insert("wd", Imf::Channel(Imf::FLOAT)); }), 7));
    EXPECT_TRUE(onlyRule(raw([](Imf::Header&, Imf::Header& m) {
                             m.channels() = Imf::ChannelList();
                             m.channels().insert("ud", Imf::Channel(Imf::HALF));
                             m.channels().insert("vd", Imf::Channel(Imf::FLOAT));
                         }),
                         7));
    EXPECT_TRUE(onlyRule(raw([](Imf::Header&, Imf::Header& m) { m.dataWindow() = Imath::Box2i({1, 0}, {5, 3}); }), 7));
}

TEST_F(RuleTest, V8ToV11MapGeometry) {
    ConusFile f = validFile();
    f.map.xy[2 * 6] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(onlyRule(validateConusFile(f), 8));
    f = validFile();
    f.map.xy[2 * 6 + 1] = -0.5f;  // node (1,1) above the top edge: outside and folded
    EXPECT_TRUE(validateConusFile(f).violates(Rule::V9));
    f = validFile();
    f.map.xy[1] = 0.01f;  // top-left corner off its edge
    EXPECT_TRUE(onlyRule(validateConusFile(f), 10));
    f = validFile();
    f.map.xy[2 * 6] = 0.6f;  // node (1,1) past (2,1): folded
    EXPECT_TRUE(onlyRule(validateConusFile(f), 11));
}

TEST_F(RuleTest, MapRulesAreCheckedInFiles) {
    ConusFile f = validFile();
    f.map.xy[2 * 6] = 0.6f;
    writeRaw(m_dir.file("fold.exr"), f, [](Imf::Header&, Imf::Header&) {});
    EXPECT_TRUE(onlyRule(validateConusFile(m_dir.file("fold.exr")), 11));
    const Error e = errorFrom([&] { readConusFile(m_dir.file("fold.exr")); });
    EXPECT_EQ(e.code(), ErrorCode::InvalidMap);
}

TEST_F(RuleTest, V12AnalyticMap) {
    ConusFile f = validFile();
    f.analytic = AnalyticMap{"foci", {{0.5, 0.5, 0.1, 100}}, "density", {}};
    EXPECT_TRUE(onlyRule(validateConusFile(f), 12));
    // A focus's radius is in (0, 1]: no wider than the image (codec's builders refuse the same).
    for (const double radius : {1.5, 1.0001, 0.0, -0.1, std::numeric_limits<double>::infinity(), std::nan("")}) {
        f.analytic = AnalyticMap{"foci", {{0.5, 0.5, radius, 2}}, "density", {}};
        EXPECT_TRUE(onlyRule(validateConusFile(f), 12)) << radius;
    }
    f.analytic = AnalyticMap{"foci", {{0.5, 0.5, 1.0, 2}}, "density", {}};
    EXPECT_TRUE(validateConusFile(f).ok()) << validateConusFile(f).str();
    f.analytic = AnalyticMap{"foci", {{0.5, 0.5, 0.1, 2}}, "multiply", {}};
    EXPECT_TRUE(onlyRule(validateConusFile(f), 12));
    f.analytic = AnalyticMap{"foci", {}, "add", {}};
    EXPECT_TRUE(onlyRule(validateConusFile(f), 12));
    f.analytic = AnalyticMap{"spiral", {}, "", {}};
    EXPECT_TRUE(onlyRule(validateConusFile(f), 12));
    f.analytic = AnalyticMap{"ground", {}, "", {{"tilt", std::numeric_limits<double>::infinity()}}};
    EXPECT_TRUE(onlyRule(validateConusFile(f), 12));
    // A focus's transition (--falloff): both scalars, the width in (1, 8], the shape 0, 1 or 2.
    f.analytic = AnalyticMap{"foci", {{0.5, 0.5, 0.1, 2}}, "density", {{"falloffWidth", 1.75}, {"falloffShape", 2}}};
    EXPECT_TRUE(validateConusFile(f).ok());
    for (const auto& params : std::vector<std::map<std::string, double>>{{{"falloffWidth", 0.5}, {"falloffShape", 0}},
                                                                         {{"falloffWidth", 20}, {"falloffShape", 0}},
                                                                         {{"falloffWidth", 1.5}, {"falloffShape", 7}},
                                                                         {{"falloffWidth", 1.5}, {"falloffShape", 1.5}},
                                                                         {{"falloffWidth", 1.5}}}) {
        f.analytic = AnalyticMap{"foci", {{0.5, 0.5, 0.1, 2}}, "density", params};
        const ValidationReport report = validateConusFile(f);
        EXPECT_TRUE(onlyRule(report, 12)) << params.begin()->second << " " << params.size();
        ASSERT_FALSE(report.issues.empty());
        EXPECT_NE(report.issues.front().message.find("falloff"), std::string::npos) << report.issues.front().message;
    }
    // The aspect a map file's foci were made for: a positive width / height.
    f.analytic = AnalyticMap{"foci", {{0.5, 0.5, 0.1, 2}}, "density", {{"aspect", 1.5}}};
    EXPECT_TRUE(validateConusFile(f).ok());
    for (const double aspect : {0.0, -1.5, 1e-9}) {
        f.analytic = AnalyticMap{"foci", {{0.5, 0.5, 0.1, 2}}, "density", {{"aspect", aspect}}};
        const ValidationReport report = validateConusFile(f);
        EXPECT_TRUE(onlyRule(report, 12)) << aspect;
        ASSERT_FALSE(report.issues.empty());
        EXPECT_NE(report.issues.front().message.find("aspect"), std::string::npos) << report.issues.front().message;
    }
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) {
                             c.insert("conus:mapKind", Imf::StringAttribute("foci"));
                             c.insert("conus:foci", Imf::FloatVectorAttribute({0.5f, 0.5f, 0.1f, 2.0f, 0.3f}));
                             c.insert("conus:composition", Imf::StringAttribute("add"));
                         }),
                         12));
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) {
                             c.insert("conus:mapKind", Imf::StringAttribute("ground"));
                             c.insert("conus:param:tilt", Imf::StringAttribute("steep"));
                         }),
                         12));
}

TEST_F(RuleTest, V13Camera) {
    ConusFile f = validFile();
    f.camera = CameraAttributes{};
    f.camera->worldToNDC[5] = std::numeric_limits<float>::quiet_NaN();
    EXPECT_TRUE(onlyRule(validateConusFile(f), 13));
    f.camera = CameraAttributes{"fisheye", {}, {}};
    EXPECT_TRUE(onlyRule(validateConusFile(f), 13));
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) {
                             c.insert("worldToCamera", Imf::M44fAttribute(Imath::M44f()));
                             c.insert("conus:projection", Imf::StringAttribute("perspective"));
                         }),
                         13));
}

TEST_F(RuleTest, V13CameraMatricesMustDescribeACamera) {
    ConusFile f = validFile();
    const conus::Camera perspective = conus::Camera::perspective({1, 2, 3}, {0, 0, 0}, {0, 1, 0}, 50, 1.5, 0.1, 100);
    f.camera = toAttributes(perspective);
    EXPECT_TRUE(validateConusFile(f).ok()) << validateConusFile(f).str();
    // The same matrices called orthographic disagree with their own projection.
    f.camera->projection = "orthographic";
    ValidationReport r = validateConusFile(f);
    EXPECT_TRUE(onlyRule(r, 13));
    EXPECT_NE(r.str().find("perspective camera, not orthographic"), std::string::npos) << r.str();
    // A singular worldToCamera (a zero row) has no inverse: no camera.
    f.camera = toAttributes(perspective);
    for (int i = 0; i < 4; ++i) f.camera->worldToCamera[4 + i] = 0.0f;
    r = validateConusFile(f);
    EXPECT_TRUE(onlyRule(r, 13));
    EXPECT_NE(r.str().find("singular"), std::string::npos) << r.str();
    // toCamera gives back the camera the attributes were written from.
    const conus::Camera back = toCamera(toAttributes(perspective));
    EXPECT_NEAR(glm::distance(back.eye(), perspective.eye()), 0.0, 1e-5);
    EXPECT_NEAR(back.verticalFovDegrees(), 50.0, 1e-3);
    EXPECT_THROW(toCamera(*f.camera), conus::Error);
}

TEST_F(RuleTest, V14Depth) {
    ConusFile f = validFile();
    f.image = makeImage(8, 6, {"Y", "Z"});
    EXPECT_TRUE(onlyRule(validateConusFile(f), 14));  // Z without depthKind
    f.depth = {DepthKind::CameraDepth, "m", 5.0f, 1.0f};
    EXPECT_TRUE(onlyRule(validateConusFile(f), 14));  // near > far
    f = validFile();
    f.depth = {DepthKind::Height, "m", 0.0f, 1.0f};
    EXPECT_TRUE(onlyRule(validateConusFile(f), 14));  // depthKind without Z
    EXPECT_TRUE(onlyRule(raw([](Imf::Header& c, Imf::Header&) { c.insert("conus:depthKind", Imf::StringAttribute("altitude")); }), 14));
}

TEST_F(RuleTest, V17DepthImageNeedsItsCamera) {
    ConusFile f = validFile();
    f.image = makeImage(8, 6, {"R", "G", "B", "A", "Z"});
    f.dataKind = DataKind::DepthImage;
    f.depth = {DepthKind::CameraDepth, "m", 0.5f, 40.0f};
    ValidationReport r = validateConusFile(f);  // no camera
    EXPECT_TRUE(onlyRule(r, 17));
    EXPECT_NE(r.str().find("missing worldToCamera, worldToNDC, conus:projection"), std::string::npos) << r.str();
    f.camera = toAttributes(conus::Camera::perspective({1, 2, 3}, {0, 0, 0}, {0, 1, 0}, 50, 8.0 / 6.0, 0.5, 40));
    EXPECT_TRUE(validateConusFile(f).ok()) << validateConusFile(f).str();
    f.depth.kind = DepthKind::Height;  // a depth image holds camera depth, not heights
    r = validateConusFile(f);
    EXPECT_TRUE(onlyRule(r, 17));
    EXPECT_NE(r.str().find("not cameraDepth"), std::string::npos) << r.str();
    // On disk: an ordinary image file relabelled `depthimage` has neither camera nor camera depth.
    r = raw([](Imf::Header& c, Imf::Header&) { c.insert("conus:dataKind", Imf::StringAttribute("depthimage")); });
    EXPECT_TRUE(onlyRule(r, 17));
    EXPECT_NE(r.str().find("missing worldToCamera"), std::string::npos) << r.str();
}

TEST_F(RuleTest, V15DisplayWindows) {
    // OpenEXR refuses to write parts with different displayWindows, so patch the second part's
    // in the bytes: name, type, size 16, then min.x min.y max.x max.y as little-endian int32.
    writeRaw(m_dir.file("raw.exr"), validFile(), [](Imf::Header&, Imf::Header&) {});
    std::string bytes;
    {
        std::ifstream in(m_dir.file("raw.exr"), std::ios::binary);
        bytes.assign(std::istreambuf_iterator<char>(in), {});
    }
    const std::string key("displayWindow\0box2i\0", 20);
    const std::size_t first = bytes.find(key);
    const std::size_t second = bytes.find(key, first + 1);
    ASSERT_NE(second, std::string::npos);
    bytes[second + key.size() + 4 + 8] = 99;  // max.x of part 1
    std::ofstream(m_dir.file("patched.exr"), std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    const ValidationReport r = validateConusFile(m_dir.file("patched.exr"));
    EXPECT_TRUE(onlyRule(r, 15));
    EXPECT_NE(r.str().find("(0, 0) - (99, 5)"), std::string::npos) << r.str();
}

}  // namespace
}  // namespace conus::format
