// A reflection asset in one file (spec "Reflection assets", V18 and V19): six depth-image faces and
// the cube's frame, written, read, validated, and refused when damaged.
#include <gtest/gtest.h>

#include <ImfMatrixAttribute.h>
#include <ImfStringAttribute.h>
#include <ImfVecAttribute.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "conus/core/camera.h"
#include "conus/format/reflection_asset.h"
#include "exr_surgery.h"
#include "raw_file.h"
#include "test_files.h"

namespace conus::format {
namespace {

using testing::TempDir;
using testing::errorFrom;

constexpr int kSize = 8;
const glm::dvec3 kCentre(0.5, -0.25, 2.0);

// Six faces around kCentre whose pixels differ by face and position (values half holds exactly);
// the +z face has a distorted map.
ReflectionAssetFile validAsset() {
    ReflectionAssetFile asset;
    asset.frame.centre = {float(kCentre.x), float(kCentre.y), float(kCentre.z)};
    for (int f = 0; f < kCubeFaceCount; ++f) {
        ConusFile& face = asset.faces[std::size_t(f)];
        face.image = makeImage(kSize, kSize, {"A", "B", "G", "R", "Z"});
        for (int y = 0; y < kSize; ++y)
            for (int x = 0; x < kSize; ++x) {
                face.image.at(x, y, 0) = 1.0f;
                for (int c = 1; c < 4; ++c) face.image.at(x, y, c) = float((f * 7 + x * 3 + y * 5 + c) % 16) / 16.0f;
                face.image.at(x, y, 4) = 1.0f + 0.37f * float(f) + 0.011f * float(x * kSize + y);
            }
        face.dataKind = DataKind::DepthImage;
        face.sourceWidth = face.sourceHeight = kSize;
        face.map = f == 4 ? testing::validFile().map : testing::identityGrid(2, 2);
        const auto& t = kCubeFaceAxes[std::size_t(f)];
        face.camera = toAttributes(Camera::perspective(kCentre, kCentre + glm::dvec3(t[0], t[1], t[2]), {t[3], t[4], t[5]}, 90.0,
                                                       1.0, 0.01, 10.0));
        face.depth = {DepthKind::CameraDepth, "world", 0.01f, 10.0f};
    }
    return asset;
}

// The report is not ok, and every issue is one of `rules`.
::testing::AssertionResult only(const ValidationReport& r, std::initializer_list<Rule> rules) {
    if (r.ok()) return ::testing::AssertionFailure() << "report is ok";
    for (const Issue& i : r.issues)
        if (std::find(rules.begin(), rules.end(), i.rule) == rules.end())
            return ::testing::AssertionFailure() << "unexpected issue: " << r.str();
    return ::testing::AssertionSuccess();
}

class ReflectionAsset : public ::testing::Test {
protected:
    // The valid asset written, then copied through `edit` (exr_surgery.h) to damaged.exr.
    std::string damaged(const std::function<bool(int, Imf::Header&)>& edit) {
        writeReflectionAsset(m_dir.file("asset.exr"), validAsset());
        test::copyExrParts(m_dir.file("asset.exr"), m_dir.file("damaged.exr"), edit);
        return m_dir.file("damaged.exr");
    }
    TempDir m_dir;
};

TEST_F(ReflectionAsset, RoundTripsThroughOneFile) {
    const ReflectionAssetFile asset = validAsset();
    ASSERT_TRUE(validateReflectionAsset(asset).ok()) << validateReflectionAsset(asset).str();
    const std::string path = m_dir.file("asset.exr");
    writeReflectionAsset(path, asset);
    EXPECT_TRUE(isReflectionAsset(path));
    EXPECT_TRUE(validateConusFile(path).ok()) << validateConusFile(path).str();
    const ReflectionAssetFile back = readReflectionAsset(path);
    EXPECT_EQ(back.frame.centre, asset.frame.centre);
    EXPECT_EQ(back.frame.axes, asset.frame.axes);
    for (std::size_t f = 0; f < back.faces.size(); ++f) {
        SCOPED_TRACE(kCubeFaceNames[f]);
        EXPECT_EQ(back.faces[f].image.channels, asset.faces[f].image.channels);
        EXPECT_EQ(back.faces[f].image.pixels, asset.faces[f].image.pixels);
        EXPECT_EQ(back.faces[f].map.xy, asset.faces[f].map.xy);
        ASSERT_TRUE(back.faces[f].camera);
        EXPECT_EQ(back.faces[f].camera->worldToNDC, asset.faces[f].camera->worldToNDC);
        EXPECT_EQ(back.faces[f].dataKind, DataKind::DepthImage);
    }
    // The header reader gives sizes and no pixels.
    const ReflectionAssetFile header = readReflectionAssetHeader(path);
    EXPECT_EQ(header.faces[5].image.width, kSize);
    EXPECT_TRUE(header.faces[5].image.pixels.empty());
    // Ordinary EXR readers see twelve named parts, each face's image before its map.
    Imf::MultiPartInputFile exr(path.c_str());
    ASSERT_EQ(exr.parts(), 2 * kCubeFaceCount);
    for (int f = 0; f < kCubeFaceCount; ++f) {
        EXPECT_EQ(exr.header(2 * f).name(), std::string("conus.") + kCubeFaceNames[f]);
        EXPECT_EQ(exr.header(2 * f + 1).name(), std::string("samplingmap.") + kCubeFaceNames[f]);
    }
    EXPECT_NE(exr.header(0).findTypedAttribute<Imf::V3fAttribute>("conus:cubeCentre"), nullptr);
    EXPECT_NE(exr.header(0).findTypedAttribute<Imf::M33fAttribute>("conus:cubeAxes"), nullptr);
}

TEST_F(ReflectionAsset, EachReaderRefusesTheOtherLayoutSayingWhatReadsIt) {
    writeReflectionAsset(m_dir.file("asset.exr"), validAsset());
    writeConusFile(m_dir.file("one.exr"), validAsset().faces[0]);
    Error e = errorFrom([&] { readConusFile(m_dir.file("asset.exr")); });
    EXPECT_EQ(e.code(), ErrorCode::NotConus);
    EXPECT_NE(std::string(e.what()).find("reflection asset"), std::string::npos) << e.what();
    e = errorFrom([&] { readReflectionAsset(m_dir.file("one.exr")); });
    EXPECT_EQ(e.code(), ErrorCode::NotConus);
    EXPECT_NE(std::string(e.what()).find("conus bake reflection"), std::string::npos) << e.what();
    EXPECT_FALSE(isReflectionAsset(m_dir.file("one.exr")));
    EXPECT_FALSE(isReflectionAsset(m_dir.file("missing.exr")));
}

TEST_F(ReflectionAsset, ABadFrameOrFaceIsRefusedInMemoryAndNothingIsWritten) {
    ReflectionAssetFile a = validAsset();
    a.frame.centre[1] = std::nanf("");
    EXPECT_TRUE(only(validateReflectionAsset(a), {Rule::V19}));
    a = validAsset();
    a.frame.centre[0] += 0.5f;  // the faces' eyes are elsewhere
    const ValidationReport moved = validateReflectionAsset(a);
    EXPECT_TRUE(only(moved, {Rule::V19}));
    EXPECT_EQ(moved.issues.size(), 1u) << moved.str();
    EXPECT_NE(moved.str().find("conus:cubeCentre (1, -0.25, 2) is not the faces' eye (0.5, -0.25, 2)"), std::string::npos) << moved.str();
    a = validAsset();
    a.faces[3].camera = toAttributes(Camera::perspective(kCentre + glm::dvec3(0, 0.5, 0), kCentre + glm::dvec3(0, -0.5, 0),
                                                         {0, 0, 1}, 90.0, 1.0, 0.01, 10.0));  // one face's eye moved
    const ValidationReport oneMoved = validateReflectionAsset(a);
    EXPECT_TRUE(only(oneMoved, {Rule::V19}));
    EXPECT_NE(oneMoved.str().find("face ny's camera has its eye at (0.5, 0.25, 2), not at the cube's centre"), std::string::npos)
        << oneMoved.str();
    a = validAsset();
    a.frame.axes = {1, 0, 0, 0, 1, 0, 0, 0.5f, 1};
    EXPECT_TRUE(only(validateReflectionAsset(a), {Rule::V19}));
    a = validAsset();
    a.frame.axes = {0, 1, 0, 1, 0, 0, 0, 0, 1};  // left-handed
    EXPECT_TRUE(only(validateReflectionAsset(a), {Rule::V19}));
    a = validAsset();
    std::swap(a.faces[0].camera, a.faces[1].camera);  // +x looks along -x
    const ValidationReport swapped = validateReflectionAsset(a);
    EXPECT_TRUE(only(swapped, {Rule::V19}));
    EXPECT_NE(swapped.str().find("face px's camera does not look along the cube's +x axis"), std::string::npos) << swapped.str();
    a = validAsset();
    a.faces[2].image = makeImage(kSize - 2, kSize - 2, {"A", "B", "G", "R", "Z"});
    a.faces[2].sourceWidth = a.faces[2].sourceHeight = kSize - 2;
    EXPECT_TRUE(only(validateReflectionAsset(a), {Rule::V18}));
    a = validAsset();
    a.faces[3].image = makeImage(kSize, kSize, {"B", "G", "R", "Z"});
    EXPECT_TRUE(only(validateReflectionAsset(a), {Rule::V18}));
    const Error e = errorFrom([&] { writeReflectionAsset(m_dir.file("bad.exr"), a); });
    EXPECT_NE(std::string(e.what()).find("V18"), std::string::npos) << e.what();
    EXPECT_FALSE(std::filesystem::exists(m_dir.file("bad.exr")));
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(m_dir.path()), std::filesystem::directory_iterator()), 0);
}

// Layers (spec "Layers"): `layer<k>.R..Z` for k = 1..L-1 in every face, the same L; a face
// with a deeper layer round-trips, a gap, a missing channel, a name that is no layer's, a fifth
// layer or a face with fewer layers is V18.
TEST_F(ReflectionAsset, LayersAreFiveChannelsEachInEveryFace) {
    const auto layered = [](int layers, int face = -1, const std::vector<std::string>& channels = {}) {
        ReflectionAssetFile a = validAsset();
        for (int f = 0; f < kCubeFaceCount; ++f) {
            std::vector<std::string> names = {"A", "B", "G", "R", "Z"};
            for (int k = 1; k < layers; ++k)
                for (const char* c : {"A", "B", "G", "R", "Z"}) names.push_back("layer" + std::to_string(k) + "." + c);
            if (f == face) names = channels;
            Image image = makeImage(kSize, kSize, names);
            for (int y = 0; y < kSize; ++y)
                for (int x = 0; x < kSize; ++x)
                    for (std::size_t c = 0; c < names.size(); ++c)
                        image.at(x, y, int(c)) = c < 5 ? a.faces[std::size_t(f)].image.at(x, y, int(c)) : 2.0f + 0.25f * float(c);
            a.faces[std::size_t(f)].image = std::move(image);
        }
        return a;
    };
    const ReflectionAssetFile three = layered(3);
    EXPECT_TRUE(validateReflectionAsset(three).ok()) << validateReflectionAsset(three).str();
    writeReflectionAsset(m_dir.file("layered.exr"), three);
    EXPECT_TRUE(validateConusFile(m_dir.file("layered.exr")).ok());
    const ReflectionAssetFile read = readReflectionAsset(m_dir.file("layered.exr"));
    EXPECT_EQ(read.faces[4].image.channels.size(), 15u);
    const int z2 = read.faces[4].image.channelIndex("layer2.Z");
    ASSERT_GE(z2, 0);
    EXPECT_EQ(read.faces[4].image.at(3, 5, z2), three.faces[4].image.at(3, 5, three.faces[4].image.channelIndex("layer2.Z")));

    const std::vector<std::string> gap = {"A", "B", "G", "R", "Z", "layer2.A", "layer2.B", "layer2.G", "layer2.R", "layer2.Z"};
    const ValidationReport gapped = validateReflectionAsset(layered(1, 2, gap));
    EXPECT_TRUE(only(gapped, {Rule::V18})) << gapped.str();
    EXPECT_NE(gapped.str().find("face py has no channel layer1.A"), std::string::npos) << gapped.str();
    const ValidationReport partial = validateReflectionAsset(layered(1, 0, {"A", "B", "G", "R", "Z", "layer1.Z"}));
    EXPECT_TRUE(only(partial, {Rule::V18})) << partial.str();
    EXPECT_TRUE(only(validateReflectionAsset(layered(1, 5, {"A", "B", "G", "R", "Z", "layerX.Z"})), {Rule::V18}));
    const ValidationReport odd = validateReflectionAsset(layered(2, 1, {"A", "B", "G", "R", "Z", "layer1.A", "layer1.B", "layer1.G",
                                                                        "layer1.R", "layer1.Z", "layer1.N"}));
    EXPECT_TRUE(only(odd, {Rule::V18})) << odd.str();
    EXPECT_NE(odd.str().find("layer1.N, not a layer's"), std::string::npos) << odd.str();
    const ValidationReport five = validateReflectionAsset(layered(5));
    EXPECT_TRUE(only(five, {Rule::V18})) << five.str();
    EXPECT_NE(five.str().find("at most 4 layers"), std::string::npos) << five.str();
    const ValidationReport fewer = validateReflectionAsset(layered(2, 3, {"A", "B", "G", "R", "Z"}));
    EXPECT_TRUE(only(fewer, {Rule::V18})) << fewer.str();
    EXPECT_NE(fewer.str().find("every face has one count of layers"), std::string::npos) << fewer.str();
}

TEST_F(ReflectionAsset, AMissingFaceIsV18) {
    const std::string path = damaged([](int p, Imf::Header&) { return p != 10 && p != 11; });  // no nz
    const ValidationReport r = validateConusFile(path);
    EXPECT_TRUE(only(r, {Rule::V18})) << r.str();
    EXPECT_NE(r.str().find("no part `conus.nz`"), std::string::npos) << r.str();
    const Error e = errorFrom([&] { readReflectionAsset(path); });
    EXPECT_EQ(e.code(), ErrorCode::Corrupt);
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
}

TEST_F(ReflectionAsset, AFaceOfAnotherSizeIsRefused) {
    const std::string path = damaged([](int p, Imf::Header& h) {
        if (p == 2) h.dataWindow() = Imath::Box2i({0, 0}, {kSize - 2, kSize - 2});
        return true;
    });
    const ValidationReport r = validateConusFile(path);
    EXPECT_TRUE(only(r, {Rule::V4, Rule::V18})) << r.str();
    EXPECT_TRUE(r.violates(Rule::V18)) << r.str();
    EXPECT_NE(r.str().find("face nx"), std::string::npos) << r.str();
}

TEST_F(ReflectionAsset, AMistypedOrMissingFrameAttributeIsV19) {
    std::string path = damaged([](int p, Imf::Header& h) {
        if (p == 0) {
            testing::eraseAttribute(h, "conus:cubeCentre");
            h.insert("conus:cubeCentre", Imf::StringAttribute("middle"));
        }
        return true;
    });
    ValidationReport r = validateConusFile(path);
    EXPECT_TRUE(only(r, {Rule::V19})) << r.str();
    EXPECT_NE(r.str().find("conus:cubeCentre has type string, expected v3f"), std::string::npos) << r.str();
    path = damaged([](int p, Imf::Header& h) {
        if (p == 0) testing::eraseAttribute(h, "conus:cubeAxes");
        return true;
    });
    r = validateConusFile(path);
    EXPECT_TRUE(only(r, {Rule::V19})) << r.str();
    EXPECT_NE(r.str().find("missing attribute conus:cubeAxes"), std::string::npos) << r.str();
    path = damaged([](int p, Imf::Header& h) {
        if (p == 0) h.insert("conus:cubeCentre", Imf::V3fAttribute(Imath::V3f(9, 9, 9)));
        return true;
    });
    EXPECT_TRUE(only(validateConusFile(path), {Rule::V19}));
    // A face's own rules are still checked, named by its face.
    path = damaged([](int p, Imf::Header& h) {
        if (p == 6) h.insert("conus:dataKind", Imf::StringAttribute("image"));
        return true;
    });
    r = validateConusFile(path);
    EXPECT_TRUE(only(r, {Rule::V18})) << r.str();
    EXPECT_NE(r.str().find("face ny has data kind image"), std::string::npos) << r.str();
}

}  // namespace
}  // namespace conus::format
