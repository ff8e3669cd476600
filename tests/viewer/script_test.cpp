#include "actions.h"
#include "script.h"

#include <gtest/gtest.h>

#include <initializer_list>
#include <string>
#include <utility>

#include "conus/core/error.h"

namespace conus::viewer {
namespace {

TEST(Actions, ChordsParse) {
    const auto g = parseChord("g");
    ASSERT_TRUE(g);
    EXPECT_EQ(g->key, "G");
    const auto se = parseChord("Shift+E");
    ASSERT_TRUE(se);
    EXPECT_TRUE(se->shift);
    EXPECT_EQ(se->key, "E");
    const auto plus = parseChord("+");
    ASSERT_TRUE(plus);
    EXPECT_EQ(plus->key, "+");
    const auto tab = parseChord("ctrl+shift+tab");
    ASSERT_TRUE(tab);
    EXPECT_TRUE(tab->ctrl && tab->shift);
    EXPECT_EQ(tab->key, "Tab");
    EXPECT_FALSE(parseChord("alt+G"));
    EXPECT_FALSE(parseChord("Gee"));
}

// Each chord of `expected` does its action in `table` (Action::None: nothing).
void expectActions(KeyTable table, std::initializer_list<std::pair<const char*, Action>> expected) {
    for (const auto& [chord, action] : expected) EXPECT_EQ(actionFor(*parseChord(chord), table), action) << chord;
}

TEST(Actions, TheKeysTheIssueAsksFor) {
    // 1 is 1:1, not a file number.
    expectActions(KeyTable::View, {{"1", Action::SourceResolution}, {"F", Action::Fit}, {"R", Action::ModeRaw},
                                   {"ctrl+R", Action::Reload}, {"F5", Action::Reload}, {"E", Action::ExposureUp},
                                   {"shift+E", Action::ExposureDown}, {"S", Action::None}, {"Tab", Action::NextFile},
                                   {"shift+Tab", Action::PreviousFile}, {"Z", Action::ToggleDepth}});
    expectActions(KeyTable::Edit, {{"E", Action::EncodeImage}, {"ctrl+S", Action::EncodeImage}, {"S", Action::SaveMap}});
    for (const char* key : {"C", "U", "W", "D", "G", "O", "H", "I", "+", "-", "Left"})
        EXPECT_NE(actionFor(*parseChord(key), KeyTable::View), Action::None) << key;
    EXPECT_NE(helpText(KeyTable::View).find("G "), std::string::npos);
    EXPECT_NE(helpText(KeyTable::Edit).find("Ctrl-S"), std::string::npos);
}

// The 3-D modes orbit with the arrows and toggle CoNUS with U; the display keys of the frame stay,
// the file and pan keys do not, and the help lists exactly what works.
TEST(Actions, SceneKeys) {
    expectActions(KeyTable::Scene, {{"Left", Action::OrbitLeft}, {"+", Action::DollyIn}, {"U", Action::ToggleConus},
                                    {"N", Action::AddFocus}, {"T", Action::NextLook}, {"F", Action::HomeCamera},
                                    {"Z", Action::ToggleDepth}, {"R", Action::ModeRaw}, {"E", Action::ExposureUp},
                                    {"Tab", Action::None}, {"W", Action::None}});
    const std::string help = helpText(KeyTable::Scene);
    EXPECT_NE(help.find("orbit"), std::string::npos);
    EXPECT_EQ(help.find("Tab"), std::string::npos);
    EXPECT_NE(help.find("Z "), std::string::npos);
}

TEST(Script, ParsesCommands) {
    const auto s = parseScript("# a comment\n\nzoom 2 at 400 300\nzoom 0.5\npan 10 -4\nkey shift+E\nwheel -2 at 5 6\n"
                               "drag 1 2 3 4\nscreenshot /tmp/a.png\nwait 3\ninspect 7 8\nquit\n");
    ASSERT_EQ(s.size(), 10u);
    EXPECT_EQ(s[0].name, "zoom");
    EXPECT_EQ(s[0].numbers, (std::vector<double>{2, 400, 300}));
    EXPECT_EQ(s[0].line, 3);
    EXPECT_EQ(s[1].numbers.size(), 1u);
    EXPECT_EQ(s[3].text, "shift+E");
    EXPECT_EQ(s[4].numbers, (std::vector<double>{-2, 5, 6}));
    EXPECT_EQ(s[6].text, "/tmp/a.png");
}

TEST(Script, RejectsBadLinesWithTheLineNumber) {
    for (const char* bad : {"zoom", "zoom -1", "pan 1", "pan 1 x", "key Hyper+Q", "fly 1 2", "screenshot", "wait -3"}) {
        try {
            parseScript(std::string("wait 1\n") + bad + "\n");
            ADD_FAILURE() << bad;
        } catch (const Error& e) {
            EXPECT_EQ(e.code(), ErrorCode::InvalidArgument);
            EXPECT_NE(std::string(e.what()).find("line 2"), std::string::npos) << e.what();
        }
    }
}

}  // namespace
}  // namespace conus::viewer
