// conus.read_mesh and conus.read_volume: scene files through sceneio, as numpy arrays. The files a
// scene file names follow sceneio/named_files.h: its own folder only, unless allow_dirs names more.
#include "scene.h"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <cstring>
#include <string>
#include <vector>

#include "conus/sceneio/mesh_file.h"
#include "conus/sceneio/volume_file.h"

namespace py = pybind11;

namespace conus::python {
namespace {

// `count` rows of `width` values copied from `data` into a new (count, width) array.
template <typename T, typename V>
py::array rows(const std::vector<V>& values, py::ssize_t width) {
    py::array_t<T> out({py::ssize_t(values.size()), width});
    if (!values.empty()) std::memcpy(out.mutable_data(), values.data(), values.size() * sizeof(V));
    return out;
}

// A reader's options with the folders its scene file's named files may also lie in.
template <class Options>
Options allowing(const std::vector<std::string>& allowDirs) {
    Options options;
    options.allowedDirs = allowDirs;
    return options;
}

// What `read` returns, run with the GIL released.
template <class Read>
auto released(Read read) {
    py::gil_scoped_release release;
    return read();
}

}  // namespace

void addSceneReaders(py::module_& m) {
    m.def(
        "read_mesh",
        [](const std::string& path, const std::vector<std::string>& allowDirs) {
            const Mesh mesh = released([&] { return sceneio::readMesh(path, allowing<sceneio::MeshReadOptions>(allowDirs)); });
            py::dict out;
            out["positions"] = rows<float>(mesh.positions, 3);
            out["normals"] = rows<float>(mesh.normals, 3);
            py::array_t<std::uint32_t> indices({py::ssize_t(mesh.indices.size() / 3), py::ssize_t(3)});
            std::memcpy(indices.mutable_data(), mesh.indices.data(), mesh.indices.size() * sizeof(std::uint32_t));
            out["indices"] = indices;
            out["colours"] = mesh.colours.empty() ? py::object(py::none()) : py::object(rows<float>(mesh.colours, 3));
            out["uvs"] = mesh.uvs.empty() ? py::object(py::none()) : py::object(rows<float>(mesh.uvs, 2));
            return out;
        },
        py::arg("path"), py::kw_only(), py::arg("allow_dirs") = std::vector<std::string>{},
        "Read a mesh file (anything Assimp reads) as a dict of arrays: positions, normals (N, 3) float32, indices\n"
        "(T, 3) uint32, colours (N, 3) or None, uvs (N, 2) or None. Files it names (buffers, material libraries)\n"
        "must lie in its own folder or one of allow_dirs, and be regular files.");
    m.def(
        "read_volume",
        [](const std::string& spec, const std::vector<std::string>& allowDirs) {
            const Volume volume = released([&] { return sceneio::readVolume(spec, allowing<sceneio::VolumeReadOptions>(allowDirs)); });
            py::array_t<float> values({py::ssize_t(volume.depth), py::ssize_t(volume.height), py::ssize_t(volume.width)});
            std::memcpy(values.mutable_data(), volume.values.data(), volume.values.size() * sizeof(float));
            return py::make_tuple(values, py::make_tuple(volume.spacing.x, volume.spacing.y, volume.spacing.z));
        },
        py::arg("spec"), py::kw_only(), py::arg("allow_dirs") = std::vector<std::string>{},
        "Read a volume (.vdb, .nrrd, .nhdr, .den or raw:WxHxD:type[:spacing]:path) as (values (D, H, W) float32,\n"
        "spacing (x, y, z)). An NRRD header's data files must lie in its own folder or one of allow_dirs.");
}

}  // namespace conus::python
