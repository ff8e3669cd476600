// OpenVDB: the one file of CoNUS that includes an OpenVDB header. A float grid (sparse or dense)
// is densified over its active voxels' bounding box, the background value everywhere inactive;
// the box is checked against the caps before the dense samples are allocated. OpenVDB's
// exceptions become conus::Error here.
#include <openvdb/openvdb.h>
#include <openvdb/io/File.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <mutex>
#include <string>
#include <system_error>

#include "conus/core/atomic_file.h"
#include "conus/core/error.h"
#include "conus/core/parallel.h"
#include "conus/sceneio/volume_file.h"

namespace conus::sceneio {
namespace {

void initializeOnce() {
    static std::once_flag flag;
    std::call_once(flag, [] { openvdb::initialize(); });
}

}  // namespace

Volume readVdbVolume(const std::string& path, const VolumeReadOptions& options) {
    const std::string what = "vdb volume '" + path + "'";
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) throw Error(ErrorCode::Io, what + ": no such file");
    initializeOnce();
    openvdb::FloatGrid::Ptr grid;
    try {
        openvdb::io::File file(path);
        file.open(false);  // no delayed loading: the file may change or go after this call
        for (auto name = file.beginName(); name != file.endName() && !grid; ++name) {
            if (!options.gridName.empty() && name.gridName() != options.gridName) continue;
            const openvdb::GridBase::Ptr base = file.readGrid(name.gridName());
            grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
            if (!grid && !options.gridName.empty())
                throw Error(ErrorCode::Unsupported, what + ": grid '" + options.gridName + "' is a " + base->valueType() +
                                                        " grid; a volume is a float grid");
        }
        file.close();
    } catch (const openvdb::Exception& e) {
        throw Error(ErrorCode::Corrupt, what + ": " + e.what());
    } catch (const std::bad_alloc&) {
        // A damaged file makes OpenVDB read garbage counts and ask for absurd buffers; a small file
        // that exhausts memory is damaged, a large one may just be too large for this machine.
        const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
        if (!ec && bytes < (std::uintmax_t{1} << 30))
            throw Error(ErrorCode::Corrupt, what + ": damaged (reading its " + std::to_string(bytes) +
                                                " bytes asked for more memory than there is)");
        throw Error(ErrorCode::LimitExceeded, what + ": not enough memory to read it");
    } catch (const std::ios_base::failure& e) {
        throw Error(ErrorCode::Corrupt, what + ": " + e.what());
    }
    if (!grid)
        throw Error(ErrorCode::Unsupported, what + (options.gridName.empty() ? ": holds no float grid"
                                                                             : ": has no grid '" + options.gridName + "'"));
    const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
    if (box.empty()) throw Error(ErrorCode::Corrupt, what + ": its float grid has no active voxel");
    const openvdb::Coord size = box.dim();
    checkDimensions(what, size.x(), size.y(), size.z(), options.maxVoxels);

    Volume volume;
    volume.width = size.x();
    volume.height = size.y();
    volume.depth = size.z();
    const openvdb::Vec3d voxel = grid->voxelSize();
    volume.spacing = {voxel.x(), voxel.y(), voxel.z()};
    volume.values.resize(static_cast<std::size_t>(size.x()) * size.y() * size.z());
    const openvdb::Coord origin = box.min();
    parallelRows(volume.depth, 0, [&](int z0, int z1) {
        openvdb::FloatGrid::ConstAccessor accessor = grid->getConstAccessor();  // one per thread: accessors cache
        for (int z = z0; z < z1; ++z)
            for (int y = 0; y < volume.height; ++y)
                for (int x = 0; x < volume.width; ++x)
                    volume.values[volume.index(x, y, z)] = accessor.getValue(origin.offsetBy(x, y, z));
    }, 1);
    checkFileVolume(volume, what);
    return volume;
}

void writeVdbVolume(const std::string& path, const Volume& volume, float background) {
    checkVolume(volume, "vdb volume '" + path + "'");
    initializeOnce();
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(background);
    grid->setName("density");
    openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(1.0);
    transform->preScale(openvdb::Vec3d(volume.spacing.x, volume.spacing.y, volume.spacing.z));
    grid->setTransform(transform);
    openvdb::FloatGrid::Accessor accessor = grid->getAccessor();
    for (int z = 0; z < volume.depth; ++z)
        for (int y = 0; y < volume.height; ++y)
            for (int x = 0; x < volume.width; ++x) {
                const float v = volume.at(x, y, z);
                if (v != background) accessor.setValue(openvdb::Coord(x, y, z), v);
            }
    // OpenVDB writes by name: into the AtomicFile's temporary (reopened through /proc, never a
    // name someone could plant), renamed over the destination once complete.
    AtomicFile out(path);
    try {
        openvdb::io::File file(out.temporaryPath());
        file.write({grid});
        file.close();
    } catch (const openvdb::Exception& e) {
        throw Error(ErrorCode::Io, "vdb volume '" + path + "': " + e.what());
    }
    out.commit();
}

}  // namespace conus::sceneio
