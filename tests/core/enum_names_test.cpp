// core/enum_names.h: names from the table beside each enum, parsing, the one-line error listing the
// choices, case rules, and subsets for commands that offer some values only.
#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "conus/core/camera.h"
#include "conus/core/color.h"
#include "conus/core/display.h"
#include "conus/core/enum_names.h"

namespace conus {
namespace {

enum class Fruit { Apple, Pear, Quince };
enum class Shout { Quiet, Loud };

constexpr auto enumNameTable(Fruit) {
    return makeEnumNameTable<Fruit>("fruit", {{Fruit::Pear, "pear"}, {Fruit::Apple, "apple"}, {Fruit::Quince, "quince"}});
}
constexpr auto enumNameTable(Shout) { return makeEnumNameTable<Shout>("shout", {{Shout::Quiet, "quiet"}, {Shout::Loud, "loud"}}, true); }

// Every table names each value once, and parsing a name gives its value back.
template <class E>
void expectRoundTrip() {
    std::set<std::string> seen;
    for (const auto& [value, name] : kEnumNameTable<E>.names) {
        EXPECT_TRUE(seen.insert(name).second) << "named twice: " << name;
        EXPECT_STREQ(enumName(value), name);
        EXPECT_EQ(parseEnum<E>(name), value) << name;
    }
    EXPECT_EQ(enumNames<E>().size(), seen.size());
}

TEST(EnumNames, CoreTablesRoundTrip) {
    expectRoundTrip<ToneMap>();
    expectRoundTrip<Transfer>();
    expectRoundTrip<SampleType>();
    expectRoundTrip<Projection>();
    expectRoundTrip<Fruit>();
    expectRoundTrip<Shout>();
    // The names the file format writes (spec/conus-format.md) stay as they are.
    EXPECT_STREQ(enumName(Transfer::Srgb), "srgb");
    EXPECT_STREQ(enumName(SampleType::Uint16), "uint16");
    EXPECT_STREQ(enumName(Projection::Orthographic), "orthographic");
    EXPECT_STREQ(enumName(ToneMap::Aces), "aces");
}

TEST(EnumNames, ChoicesFollowTheTableOrder) {
    EXPECT_EQ(enumNames<Fruit>(), (std::vector<std::string>{"pear", "apple", "quince"}));
    EXPECT_EQ(enumChoices<Fruit>(), "pear, apple, quince");
    EXPECT_EQ(enumNames({Fruit::Quince, Fruit::Pear}), (std::vector<std::string>{"quince", "pear"}));
    EXPECT_STREQ(enumName(static_cast<Fruit>(7)), "unknown");
}

TEST(EnumNames, ParseRefusesWithOneLineListingTheChoices) {
    for (const char* bad : {"", "Pear", "pear ", "fig", "pea"}) {
        EXPECT_FALSE(tryParseEnum<Fruit>(bad)) << bad;
        try {
            parseEnum<Fruit>(bad);
            ADD_FAILURE() << "accepted '" << bad << "'";
        } catch (const Error& e) {
            const std::string message = e.what();
            EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
            EXPECT_EQ(message, "fruit '" + std::string(bad) + "' is not one of pear, apple, quince");
            EXPECT_EQ(message.find('\n'), std::string::npos);
        }
    }
}

TEST(EnumNames, AnyCaseOnlyWhereTheTableSaysSo) {
    EXPECT_EQ(parseEnum<Shout>("LOUD"), Shout::Loud);
    EXPECT_EQ(parseEnum<Shout>("QuIeT"), Shout::Quiet);
    EXPECT_FALSE(tryParseEnum<Shout>("loud!"));
    EXPECT_FALSE(tryParseEnum<Fruit>("APPLE"));
    EXPECT_FALSE(tryParseEnum<ToneMap>("Reinhard"));
}

// --bits names a picture's sample type from SampleType's own table: integers by their bits, floats
// by their names; uint32 (no picture format writes it) and SampleType's integer names are not --bits.
TEST(EnumNames, PictureBitsComeFromTheSampleTypes) {
    EXPECT_EQ(pictureBitsNames(), (std::vector<std::string>{"8", "16", "half", "float"}));
    for (SampleType t : kPictureSampleTypes) EXPECT_EQ(parsePictureBits(pictureBitsName(t)), t);
    EXPECT_EQ(pictureBitsName(SampleType::Half), std::string(enumName(SampleType::Half)));
    EXPECT_FALSE(parsePictureBits("32"));
    EXPECT_FALSE(parsePictureBits("uint8"));
    EXPECT_FALSE(parsePictureBits(""));
}

}  // namespace
}  // namespace conus
