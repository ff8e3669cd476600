// The sampling-map rules V7..V11 (spec/conus-format.md) in words. Whether a grid is valid is
// core/map_rules.h's isValidGrid, the question codec asks too; this only says what is broken.
#include <cstdio>
#include <string>

#include "conus/core/map_rules.h"
#include "conus/format/container.h"

namespace conus::format {
namespace {

// Each rule reports at most this many problems, then one summary line, so that a broken grid at the
// size limit yields a readable report instead of megabytes.
constexpr int kMaxMessagesPerRule = 20;

// Adds messages for one rule up to the cap, and the "... and N more" line at the end.
class CappedRule {
public:
    CappedRule(ValidationReport& report, Rule rule, const char* what)
        : m_report(report), m_rule(rule), m_what(what) {}
    ~CappedRule() {
        if (m_count > kMaxMessagesPerRule) {
            m_report.add(m_rule, "... and " + std::to_string(m_count - kMaxMessagesPerRule) + " more " + m_what,
                         m_count - kMaxMessagesPerRule);
        }
    }
    void add(std::string message) {
        if (++m_count <= kMaxMessagesPerRule) m_report.add(m_rule, std::move(message));
    }

private:
    ValidationReport& m_report;
    Rule m_rule;
    const char* m_what;
    long long m_count = 0;
};

std::string node(int i, int j) {
    // Built by appending: g++ 12 gives a false -Wrestrict warning for "literal" + std::string&&.
    std::string s(1, '(');
    s.append(std::to_string(i)).append(1, ',').append(std::to_string(j)).append(1, ')');
    return s;
}

}  // namespace

ValidationReport validateGrid(const GridNodes& grid) {
    ValidationReport report;
    const int n = grid.columns;
    const int m = grid.rows;
    if (map_rules::isValidGrid(n, m, grid.xy)) return report;
    if (!map_rules::sidesInRange(n, m)) {
        report.add(Rule::V7, "map grid is " + std::to_string(n) + "x" + std::to_string(m) + " nodes; columns and rows must be in [" +
                          std::to_string(kMinMapSide) + ", " + std::to_string(kMaxMapSide) + "]");
        return report;  // nothing below can be indexed safely
    }
    const std::size_t expected = std::size_t{2} * n * m;
    if (grid.xy.size() != expected) {
        report.add(Rule::V7, "map grid " + std::to_string(n) + "x" + std::to_string(m) + " needs " + std::to_string(expected) +
                          " values, has " + std::to_string(grid.xy.size()));
        return report;
    }
    const map_rules::GridView view{n, m, grid.xy.data()};

    bool allFinite = true;
    {
        CappedRule v8(report, Rule::V8, "nodes");
        CappedRule v9(report, Rule::V9, "nodes");
        CappedRule v10(report, Rule::V10, "nodes");
        for (int j = 0; j < m; ++j) {
            for (int i = 0; i < n; ++i) {
                const double u = view.u(i, j), v = view.v(i, j);
                if (!map_rules::nodeFinite(view, i, j)) {
                    v8.add("node " + node(i, j) + " is not finite: (" + numberText(u, 9) + ", " + numberText(v, 9) + ")");
                    allFinite = false;
                    continue;
                }
                if (!map_rules::nodeInside(view, i, j)) {
                    v9.add("node " + node(i, j) + " = (" + numberText(u, 9) + ", " + numberText(v, 9) + ") is outside [0,1]^2");
                }
                // Boundary nodes sit exactly on their edge, so the CoNUS image covers exactly the
                // conventional field of view; the message names the edge.
                if (map_rules::nodeOnItsEdge(view, i, j)) continue;
                if (i == 0 && u != 0.0) v10.add("left-column node " + node(i, j) + " has u = " + numberText(u, 9) + ", must be 0");
                if (i == n - 1 && u != 1.0) v10.add("right-column node " + node(i, j) + " has u = " + numberText(u, 9) + ", must be 1");
                if (j == 0 && v != 0.0) v10.add("top-row node " + node(i, j) + " has v = " + numberText(v, 9) + ", must be 0");
                if (j == m - 1 && v != 1.0) v10.add("bottom-row node " + node(i, j) + " has v = " + numberText(v, 9) + ", must be 1");
            }
        }
    }
    if (!allFinite) return report;  // cross products of NaN say nothing useful

    // V11: at every corner of every cell the cross product of the incoming and outgoing edge is
    // positive, as for the identity. A bilinear patch has a positive Jacobian everywhere iff it
    // does at its four corners, so this is exactly injectivity of the piecewise-bilinear map.
    CappedRule v11(report, Rule::V11, "cells");
    for (int j = 0; j + 1 < m; ++j) {
        for (int i = 0; i + 1 < n; ++i) {
            const int c = map_rules::firstBadCorner(view, i, j);
            if (c >= 0) {
                v11.add("cell " + node(i, j) + " is not strictly convex: corner " +
                        node(i + map_rules::kCornerDi[c], j + map_rules::kCornerDj[c]) +
                        " cross = " + numberText(map_rules::cornerCross(view, i, j, c), 9));
            }
        }
    }
    return report;
}

}  // namespace conus::format
