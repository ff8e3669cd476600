// conus.Map and conus.importance (maps.h).
#include "maps.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include "conus/codec/builders/auto_map.h"
#include "conus/codec/builders/foci.h"
#include "conus/codec/builders/frame_budget.h"
#include "conus/codec/builders/map_measures.h"
#include "conus/codec/builders/springs.h"
#include "conus/core/error.h"
#include "conus/core/map_rules.h"
#include "conus/imageio/image_file.h"
#include "arguments.h"

namespace py = pybind11;

namespace conus::python {
namespace {

using FloatArray = py::array_t<float, py::array::c_style | py::array::forcecast>;
// ---- points ------------------------------------------------------------------------------------

using DoubleArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

// f applied to every (u, v) of an (..., 2) array, without the GIL.
template <class F>
py::array mapPoints(const py::array& input, F&& f) {
    requireReal(input, "points");
    const DoubleArray points = DoubleArray::ensure(input);
    if (!points || points.ndim() < 1 || points.shape(points.ndim() - 1) != 2)
        throw Error(ErrorCode::InvalidArgument, "points must be an array of shape (..., 2)");
    for (py::ssize_t i = 0; i < points.size(); ++i)
        if (!std::isfinite(points.data()[i]))
            throw Error(ErrorCode::InvalidArgument, "points must be finite; point " + std::to_string(i / 2) + " holds " +
                                                        numberText(points.data()[i]));
    DoubleArray out(std::vector<py::ssize_t>(points.shape(), points.shape() + points.ndim()));
    const double* in = points.data();
    double* o = out.mutable_data();
    const py::ssize_t n = points.size() / 2;
    {
        py::gil_scoped_release release;
        for (py::ssize_t i = 0; i < n; ++i) {
            const glm::dvec2 q = f(glm::dvec2(in[2 * i], in[2 * i + 1]));
            o[2 * i] = q.x;
            o[2 * i + 1] = q.y;
        }
    }
    return out;
}


}  // namespace

Image pictureImportance(codec::ImportanceRule rule, const Image& picture) {
    return codec::ruleImportance(rule, imageio::displayEncoded(picture));
}

void addMaps(py::module_& m) {
    py::class_<Map, std::shared_ptr<Map>>(m, "Map", "A sampling map: a grid of distorted node positions (Equation 1)")
        .def_static(
            "identity", [](int columns, int rows) { return std::make_shared<Map>(Map{codec::SamplingMap::identity(columns, rows), {}, std::nullopt}); },
            py::arg("columns") = map_rules::kDefaultSide, py::arg("rows") = map_rules::kDefaultSide)
        .def_static(
            "foci",
            [](py::object foci, double aspect, int grid, const std::string& composition, const std::string& falloff) {
                const std::vector<codec::Focus> f = fociFrom(foci);
                codec::FociOptions options;
                options.aspect = aspect;
                options.columns = options.rows = grid;
                options.falloff = codec::parseFalloff(falloff);
                options.composition = enumArgument<codec::FociComposition>(composition, "composition");
                py::gil_scoped_release release;
                codec::SamplingMap map = codec::buildFociMap(f, options);
                return std::make_shared<Map>(Map{std::move(map), codec::toAnalytic(f, options.composition, options.falloff), aspect});
            },
            py::arg("foci"), py::arg("aspect") = 1.0, py::arg("grid") = map_rules::kDefaultSide, py::arg("composition") = enumName(codec::FociComposition::Density),
            py::arg("falloff") = codec::falloffText(codec::FociFalloff{}),
            "Circular foci (u, v, r, k): centre, radius as a fraction of the width, magnification; aspect: the pictures' "
            "width / height (encode warns on another); falloff as `map foci --falloff` (\"1.25\", the default: density "
            "smoothstepped from r to 1.25 r, widened where the anisotropy bound needs; \"2\", \"1.5,log\", \"3,logr\")")
        .def_static(
            "springs",
            [](const std::vector<std::tuple<double, double, double, double>>& strokes, int grid, int max_steps) {
                codec::SpringSystem system(grid, grid);
                for (const auto& [u, v, radius, strength] : strokes) system.addStroke({u, v, radius, strength});
                py::gil_scoped_release release;
                system.runUntilStable(max_steps);
                return std::make_shared<Map>(Map{system.toMap(grid, grid), {}, std::nullopt});
            },
            py::arg("strokes"), py::arg("grid") = map_rules::kDefaultSide, py::arg("max_steps") = 200000,
            "The paper's mass-spring brush: strokes (u, v, radius, strength), relaxed until stable")
        .def_static(
            "auto",
            [](const py::array& importance, int grid, double min_density, double max_density, double smoothing) {
                Image image = dataFrom(importance, "importance");
                const double aspect = double(image.width) / image.height;
                codec::AutoMapOptions options;
                options.columns = options.rows = grid;
                options.minDensity = min_density;
                options.maxDensity = max_density;
                options.smoothing = smoothing;
                py::gil_scoped_release release;
                return std::make_shared<Map>(Map{codec::buildAutoMap(image, options), {}, aspect});
            },
            py::arg("importance"), py::arg("grid") = map_rules::kDefaultSide, py::arg("min_density") = 0.25,
            py::arg("max_density") = 16.0, py::arg("smoothing") = codec::AutoMapOptions{}.smoothing,
            "A map whose density follows an importance image (H, W), smoothed over `smoothing` of the width")
        .def_static(
            "auto_for_frame_loss",
            [](const py::array& importance, const py::array& source, std::pair<int, int> size, double frame_loss, int grid,
               double max_density, double max_anisotropy) {
                const Image image = dataFrom(importance, "importance");
                const Image picture = pixelsFrom(source, std::nullopt, "source");
                codec::AutoMapOptions options;
                options.columns = options.rows = grid;
                options.maxDensity = max_density;
                options.maxAnisotropy = max_anisotropy;
                py::gil_scoped_release release;
                const codec::FrameErrorModel model(picture, size.first, size.second, image);
                codec::BudgetResult r = codec::buildAutoMapForFrameLoss(image, model, frame_loss, options);
                return std::make_tuple(std::make_shared<Map>(Map{std::move(r.map), {}, double(picture.width) / picture.height}),
                                       r.minDensity, r.predicted.frameLoss,
                                       r.predicted.roiGain);
            },
            py::arg("importance"), py::arg("source"), py::arg("size"), py::arg("frame_loss"),
            py::arg("grid") = map_rules::kDefaultSide, py::arg("max_density") = 16.0, py::arg("max_anisotropy") = 0.0,
            "The automatic map (max_anisotropy: 0 none, else as --max-anisotropy) with the lowest context floor whose whole-frame loss against the uniform "
            "image of `size` (width, height), chosen on the picture's band model and confirmed by encodes fitted as encode's default, stays within `frame_loss` dB as the "
            "map's own encode measures it (where no map measured holds it, the nearest): (map, floor, loss, ROI gain), both that encode's measure")
        .def_static(
            "from_nodes",
            [](const py::array& nodes) {
                requireReal(nodes, "nodes");
                const FloatArray a = FloatArray::ensure(nodes);
                if (!a || a.ndim() != 3 || a.shape(2) != 2)
                    throw Error(ErrorCode::InvalidArgument, "nodes must have shape (rows, columns, 2)");
                format::GridNodes grid;
                grid.rows = int(a.shape(0));
                grid.columns = int(a.shape(1));
                grid.xy.assign(a.data(), a.data() + a.size());
                return std::make_shared<Map>(Map{codec::SamplingMap::fromGrid(grid), {}, std::nullopt});
            },
            py::arg("nodes"), "A map from its nodes' distorted positions, shape (rows, columns, 2); validated")
        .def_property_readonly("columns", [](const Map& self) { return self.map.columns(); })
        .def_property_readonly("rows", [](const Map& self) { return self.map.rows(); })
        .def_property_readonly(
            "nodes",
            [](py::object self) {
                const Map& map = self.cast<const Map&>();
                py::array_t<float> view({py::ssize_t(map.map.rows()), py::ssize_t(map.map.columns()), py::ssize_t(2)},
                                        reinterpret_cast<const float*>(map.map.nodes().data()), self);
                py::detail::array_proxy(view.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
                return view;
            },
            "The nodes' distorted positions, (rows, columns, 2), a read-only view")
        .def("distort", [](const Map& self, const py::array& p) { return mapPoints(p, [&](glm::dvec2 q) { return self.map.distort(q); }); },
             py::arg("points"), "Equation 1 on an (..., 2) array of undistorted (u, v)")
        .def("undistort",
             [](const Map& self, const py::array& p) { return mapPoints(p, [&](glm::dvec2 q) { return self.map.undistort(q); }); },
             py::arg("points"), "The exact inverse of distort on an (..., 2) array")
        .def("density",
             [](const Map& self, const py::array& p) {
                 py::array both = mapPoints(p, [&](glm::dvec2 q) { return glm::dvec2(self.map.density(q), 0.0); });
                 return py::object(both[py::make_tuple(py::ellipsis(), 0)]).cast<py::array>();
             },
             py::arg("points"), "Sampling density (area ratio) at undistorted points")
        .def(
            "measures",
            [](const Map& self, double aspect) {
                const codec::MapMeasures m = codec::measureMap(self.map, aspect);
                py::dict d;
                d["min_cell_density"] = m.minCellDensity;
                d["max_cell_density"] = m.maxCellDensity;
                d["max_anisotropy"] = m.maxAnisotropy;
                d["most_anisotropic"] = py::make_tuple(m.mostAnisotropic.x, m.mostAnisotropic.y);
                return d;
            },
            py::arg("aspect") = 1.0,
            "What the map achieves on its own grid (as `conus info`): min/max cell density, the largest anisotropy of a "
            "cell (its Jacobian's singular value ratio in pixels of an image of this width / height) and where")
        .def("__repr__", [](const Map& self) {
            return "<conus.Map " + std::to_string(self.map.columns()) + "x" + std::to_string(self.map.rows()) + " nodes" +
                   (self.analytic ? ", " + self.analytic->kind : std::string()) + ">";
        });

    m.def(
        "importance",
        [](py::object pixels, const std::string& kind, py::object channels) {
            const Image image = pixelsFrom(pixels, channelsFrom(channels), "pixels");
            const std::optional<codec::ImportanceRule> rule = tryParseEnum<codec::ImportanceRule>(kind);
            if (!rule) throw Error(ErrorCode::InvalidArgument, "importance: kind '" + kind + "' is not one of " + enumChoices<codec::ImportanceRule>());
            py::gil_scoped_release release;
            Image out = pictureImportance(*rule, image);
            py::gil_scoped_acquire acquire;
            return toArray(std::move(out));
        },
        py::arg("pixels"), py::arg("kind") = enumName(codec::ImportanceRule::Detail), py::arg("channels") = py::none(),
        "The picture's own importance for Map.auto, as `--importance KIND`: \"detail\", the gradient magnitude of\n"
        "its display-encoded luminance, or \"faces\", a soft disc over each face found in it (conus.Error when\n"
        "none is); (H', W', 1) at most 1024 px a side");
}

}  // namespace conus::python
