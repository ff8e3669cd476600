// One way to name an enumeration: a table of value/name pairs beside the enum, from which come
// its name, its parsing, the one-line error that lists the choices, and the choices a command line
// or Python offers. A name is written once, in its table; nothing else spells it.
//
// A named enum E has, in its own namespace next to its definition, a function that returns its
// table (found by argument-dependent lookup):
//     constexpr auto enumNameTable(ToneMap) {
//         return makeEnumNameTable<ToneMap>("tone map", {{ToneMap::None, "none"}, {ToneMap::Reinhard, "reinhard"}});
//     }
// `what` names the enum in messages; the pairs' order is the order choices are listed in; a last
// argument `true` makes parsing ignore ASCII case (the names themselves are lower case then).
#pragma once

#include <array>
#include <cstddef>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "conus/core/error.h"

namespace conus {

template <class E, std::size_t N>
struct EnumNameTable {
    const char* what;
    std::array<std::pair<E, const char*>, N> names;
    bool anyCase;
};

template <class E, std::size_t N>
constexpr EnumNameTable<E, N> makeEnumNameTable(const char* what, const std::pair<E, const char*> (&names)[N], bool anyCase = false) {
    EnumNameTable<E, N> table{what, {}, anyCase};
    for (std::size_t i = 0; i < N; ++i) table.names[i] = names[i];
    return table;
}

namespace enum_names_detail {
inline bool sameName(std::string_view text, std::string_view name, bool anyCase) {
    if (text.size() != name.size()) return false;
    for (std::size_t i = 0; i < text.size(); ++i) {
        char c = text[i];
        if (anyCase && c >= 'A' && c <= 'Z') c = char(c - 'A' + 'a');
        if (c != name[i]) return false;
    }
    return true;
}
}  // namespace enum_names_detail

// E's table: what its enumNameTable returns (a constant, built once).
template <class E>
inline constexpr auto kEnumNameTable = enumNameTable(E{});

// The name of `value` ("unknown" for a value outside the table, e.g. one cast from a bad integer).
template <class E>
const char* enumName(E value) {
    for (const auto& [v, name] : kEnumNameTable<E>.names)
        if (v == value) return name;
    return "unknown";
}

// The value named `text`, or nothing.
template <class E>
std::optional<E> tryParseEnum(std::string_view text) {
    for (const auto& [v, name] : kEnumNameTable<E>.names)
        if (enum_names_detail::sameName(text, name, kEnumNameTable<E>.anyCase)) return v;
    return std::nullopt;
}

// Every name in table order, or the names of `values` only (a command that offers some): for
// CLI11's IsMember and Python's accepted lists.
template <class E>
std::vector<std::string> enumNames() {
    std::vector<std::string> names;
    for (const auto& entry : kEnumNameTable<E>.names) names.emplace_back(entry.second);
    return names;
}
template <class E>
std::vector<std::string> enumNames(std::initializer_list<E> values) {
    std::vector<std::string> names;
    for (E value : values) names.emplace_back(enumName(value));
    return names;
}

// "none, reinhard, aces": the choices for a message or a help text.
template <class E>
std::string enumChoices() {
    std::string list;
    for (const auto& entry : kEnumNameTable<E>.names) list.append(list.empty() ? "" : ", ").append(entry.second);
    return list;
}

// The value named `text`; else throws conus::Error(InvalidArgument), one line:
// "tone map 'x' is not one of none, reinhard, aces".
template <class E>
E parseEnum(std::string_view text) {
    if (const std::optional<E> value = tryParseEnum<E>(text)) return *value;
    throw Error(ErrorCode::InvalidArgument,
                std::string(kEnumNameTable<E>.what) + " '" + std::string(text) + "' is not one of " + enumChoices<E>());
}

}  // namespace conus
