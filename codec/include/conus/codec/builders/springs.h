// The paper's mass-spring brush system (section 3.1, Figure 8): a grid of particles joined by
// springs along the grid edges; brush strokes push neighbouring particles apart, and the rest
// positions of the particles become a sampling map. Step-wise, for an interactive viewer: add
// strokes, step, look at positions(), and stop when stable().
//
// Model (all coordinates normalized, particle (i,j) starting at (i/(columns-1), j/(rows-1))):
// - Equal masses m; springs of stiffness k along grid edges with rest length 10% of the initial
//   spacing (the paper's choice: every spring is under tension, so the mesh is taut and the
//   identity is an equilibrium); velocity damping c (force -c v).
// - Boundary particles slide along their edge (their normal coordinate is exactly 0 or 1), the
//   four corners are fixed.
// - A stroke (u, v, radius, strength, duration) acts on the springs whose rest midpoint lies in
//   the disc: it adds a repulsive pair force strength * w(d/radius) * k * spacing along the spring,
//   w(s) = (exp(-4 s^2) - exp(-4)) / (1 - exp(-4)), 1 at the centre falling exponentially to 0 at
//   the rim. The brush is "painted" in: the force ramps up linearly over `duration` simulated
//   seconds from the moment the stroke is added and then stays, so the magnification persists
//   once the stroke has finished. strength s lengthens a spring at the centre by about s rest
//   spacings: strength 1 roughly doubles the spacing there (density about 4 at the centre).
//   Brush coordinates are undistorted (the conventional image); a viewer undistorts a click on the
//   current map before adding a stroke there.
// - Integrator: semi-implicit (symplectic) Euler, v += dt F/m, x += dt v, with the damping term
//   taken implicitly (v /= 1 + c dt / m). Explicit Euler amplifies every undamped oscillation mode
//   by sqrt(1 + (w dt)^2) per step and relies on damping to survive; symplectic Euler is stable for
//   w_max dt < 2 at the same cost. The automatic step is dt = 1 / w_max with w_max = sqrt(8 k / m),
//   the highest frequency of the grid (4 springs per particle, 2 directions).
// - Injectivity: after every step each cell must stay strictly convex with the identity's
//   orientation, with a margin (every corner cross product above 1e-3 of its rest value). The
//   particles of a cell that would break this are put back where they were and stopped (a contact
//   constraint), repeated over the cells around them until every cell passes. The previous state
//   passed, so positions() always forms a valid map; strokes of any strength cannot fold it.
//   stable() ignores the force on particles held back in the last step (the constraint holds it).
// - runUntilStable() (SpringOptions::multilevel, the default) only wants the equilibrium: it
//   paints in what is left of the strokes at once, solves the same strokes on a half-resolution
//   system (recursively while both sides are >= 66), prolongs that equilibrium bilinearly as a
//   warm start (kept only if every cell passes the guard, else moved part of the way), then relaxes
//   with steps of 1.9 / w_max (still guarded, same damping). step() is unchanged. stable() is
//   meaningful: at the default tolerances plain stepping stops within ~0.01 spacings of a state
//   stepped 200,000 more steps.
// - Deterministic: one thread, a fixed order of operations; the same strokes give the same
//   positions bit for bit.
//
// Stroke files (parseStrokes) are a JSON list of objects, one per stroke, added in order:
//   [{"u":0.3,"v":0.4,"radius":0.1,"strength":1.0,"duration":0.5}, ...]
// u, v in [0,1]; radius in (0, 2]; strength in [0, 1000]; duration in [0, 3600] seconds, optional
// (default 0.5). Unknown keys are an error (a typo should not be silently ignored).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "conus/codec/map/sampling_map.h"
#include "conus/core/error.h"

namespace conus::codec {

struct Stroke {
    double u = 0.5, v = 0.5;  // brush centre, undistorted normalized coordinates
    double radius = 0.1;      // brush radius, normalized (a disc in (u,v))
    double strength = 1.0;    // extra spring extension at the centre, in rest spacings
    double duration = 0.5;    // simulated seconds over which the stroke is painted in
};

struct SpringOptions {
    double stiffness = 1000.0;    // k, force per unit of extension
    double mass = 1.0;            // m, every particle
    double damping = -1.0;        // c; negative: automatic (see springs.cpp)
    double restFraction = 0.1;    // rest length / initial spacing (the paper's 10%)
    double timeStep = 0.0;        // dt in simulated seconds; 0: automatic 1 / sqrt(8 k / m)
    // stable(): every particle moves less than this many rest spacings per step, and its force is
    // below forceTolerance * k * spacing.
    double speedTolerance = 2e-5;
    double forceTolerance = 2e-3;
    // runUntilStable() warm-starts from the equilibrium of a half-resolution system (recursively,
    // down to about 33 particles a side) before relaxing with step(). Off: plain stepping only.
    bool multilevel = true;
};

// Throws conus::Error(InvalidArgument) naming the field that is out of range.
void checkStroke(const Stroke& stroke);

// Parses a stroke list (format above); throws conus::Error(InvalidArgument) for bad JSON, a
// missing or non-numeric field, an unknown key or an out-of-range value, naming the stroke.
std::vector<Stroke> parseStrokes(const std::string& jsonText);

class SpringSystem {
public:
    // columns x rows particles, each in [kMinMapSide, kMaxMapSide]; throws conus::Error(InvalidArgument) for bad
    // sizes or options.
    SpringSystem(int columns, int rows, const SpringOptions& options = {});

    // Starts painting a stroke at the current simulated time (checked by checkStroke).
    void addStroke(const Stroke& stroke);
    void step(int n = 1);
    // True once every stroke has finished and the state is at rest (tolerances in the options).
    bool stable() const;
    // Steps until stable() or maxSteps; returns the number of steps taken. Reports the fraction
    // of maxSteps done (stopping early jumps to 1).
    int runUntilStable(int maxSteps, const ProgressFn& progress = {});

    int columns() const { return m_columns; }
    int rows() const { return m_rows; }
    double time() const { return m_time; }
    double timeStep() const { return m_dt; }
    double damping() const { return m_damping; }
    std::int64_t steps() const { return m_steps; }
    // Work of the coarse-grid warm starts done by runUntilStable(), in steps of this grid (a
    // coarse step costs its particle count over this grid's).
    double warmStartWork() const { return m_warmWork; }
    // Particles held back by the injectivity guard in the last step.
    int heldBack() const { return static_cast<int>(m_held.size()); }

    // Particle positions, row-major (particle (i,j) at j*columns+i): always a valid map.
    std::vector<glm::vec2> positions() const;
    // The map: the particle grid itself (same size), or a resampling of it (Eq. 1 on the particle
    // grid). A coarser grid of a valid map can fold where the map bends sharply; then the
    // displacements are scaled down by the compose.h rule and *scale (when given) says by what.
    SamplingMap toMap(int columns, int rows, double* scale = nullptr) const;
    SamplingMap toMap() const { return toMap(m_columns, m_rows); }

private:
    struct ActiveStroke {
        Stroke stroke;
        double start = 0.0;
    };
    void depositStrokes(double dt, bool finish = false);
    void warmStart(int maxSteps);
    void computeForces();
    void integrate(double dt, double damping);
    void advance(double dt, double damping);
    void guard();
    bool cellOk(int i, int j) const;
    void holdBack(int k);

    int m_columns = 0, m_rows = 0;
    SpringOptions m_options;
    double m_dt = 0.0, m_damping = 0.0, m_time = 0.0;
    double m_relaxDt = 0.0, m_relaxDamping = 0.0;  // runUntilStable's steps (multilevel)
    std::int64_t m_steps = 0;
    float m_hx = 0, m_hy = 0;             // rest spacing
    double m_minCross = 0.0;              // guard margin on corner cross products
    // Displacements from the rest (identity) positions, not positions: near rest they are small,
    // so float resolves them far below a spacing (an 0.7 coordinate would jitter by its ulp).
    std::vector<float> m_x, m_y;
    std::vector<float> m_nx, m_ny;        // displacements after the step being taken
    std::vector<float> m_vx, m_vy;        // velocities
    std::vector<float> m_fx, m_fy;        // forces of the last step
    std::vector<float> m_sx, m_sy;        // spring forces: horizontal springs then vertical ones
    std::vector<float> m_repH, m_repV;    // brush repulsion per horizontal / vertical spring
    std::vector<std::uint8_t> m_heldFlag; // per particle: held back in the current step
    std::vector<int> m_held;              // particles held back in the last step
    std::vector<int> m_work, m_next;      // guard work lists (cells)
    std::vector<ActiveStroke> m_strokes;  // strokes still being painted in
    std::vector<Stroke> m_allStrokes;     // every stroke added, for the coarse warm-start systems
    bool m_warmDone = true;               // no stroke added since the last warm start
    bool m_stepped = true;                // a step since the last warm start (stable() needs one)
    double m_warmWork = 0.0;
};

}  // namespace conus::codec
