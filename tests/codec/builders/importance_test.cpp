// The importance rules by name (importance.h): the names the CLI and Python accept, and each rule
// reached through ruleImportance, the faces module loaded from this library's own folder.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "conus/codec/builders/importance.h"
#include "conus/core/error.h"

namespace conus::codec {
namespace {

TEST(Importance, RulesGoByTheirNames) {
    EXPECT_EQ(enumNames<ImportanceRule>(), (std::vector<std::string>{"detail", "faces"}));
    for (ImportanceRule rule : {ImportanceRule::Detail, ImportanceRule::Faces})
        EXPECT_EQ(tryParseEnum<ImportanceRule>(enumName(rule)), rule);
    EXPECT_STREQ(enumName(ImportanceRule::Faces), "faces");
    EXPECT_FALSE(tryParseEnum<ImportanceRule>("Detail"));  // names are exact, as the CLI's choices
    EXPECT_FALSE(tryParseEnum<ImportanceRule>("saliency"));
    EXPECT_FALSE(tryParseEnum<ImportanceRule>(""));
    EXPECT_EQ(enumChoices<ImportanceRule>(), "detail, faces");
}

// A display-encoded grey picture, 0.3, with a white square on the right half's top.
Image squareOnTheRight() {
    Image shown = makeImage(120, 80, {"R", "G", "B"});
    for (float& v : shown.pixels) v = 0.3f;
    for (int y = 10; y < 40; ++y)
        for (int x = 80; x < 110; ++x)
            for (int c = 0; c < 3; ++c) shown.at(x, y, c) = 1.0f;
    return shown;
}

TEST(Importance, DetailIsTheSquaresOutline) {
    const Image detail = ruleImportance(ImportanceRule::Detail, squareOnTheRight());
    ASSERT_EQ(detail.width, 120);
    EXPECT_GT(detail.at(80, 25), 1.0f);   // its left edge
    EXPECT_EQ(detail.at(95, 25), 0.0f);   // inside
    EXPECT_EQ(detail.at(20, 60), 0.0f);   // the flat left
}

TEST(Importance, FacesRefuseAPictureWithoutAFace) {
    // The detector's module is found beside libconus_codec and finds nothing here: Unsupported
    // (the picture decides, exit 1), not a crash or an empty map.
    try {
        ruleImportance(ImportanceRule::Faces, squareOnTheRight());
        FAIL() << "no face, yet no error";
    } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::Unsupported);
        EXPECT_NE(std::string(e.what()).find("no face found"), std::string::npos) << e.what();
    }
}

}  // namespace
}  // namespace conus::codec
