// [source], [target] (mesh or volume, grids, transform, colour), [[prop]] and [volume].
#include "TableParsers.h"

#include <volmorph/Frames.h>

#include <limits>

namespace volmorph::detail {

void parseFile(Reader& r, const toml::node& n, const std::string& path,
               const std::filesystem::path& folder, std::filesystem::path& file,
               SourceLocation& where)
{
    const std::optional<std::string> s = r.string(n, path);
    if (!s) return;
    where = r.at(n);
    const std::filesystem::path p(*s);
    file = p.is_absolute() ? p : folder / p;
    std::error_code ec;
    if (s->empty())
        r.error(r.at(n), path + ": expected a file name");
    else if (!std::filesystem::is_regular_file(file, ec))
        r.error(r.at(n), path + ": file not found: '" + *s + "' (looked for " + file.string() + ")",
                file.string());
}

namespace {

const std::vector<std::string> kObjectKeys = {"mesh",      "volume", "grids",
                                              "transform", "color",  "window"};
const std::vector<std::string> kGridKeys = {"density", "sdf", "color"};
const std::vector<std::string> kTransformKeys = {"translate", "rotate", "scale"};
const std::vector<std::string> kVolumeKeys = {"voxel_size", "resolution"};
const std::vector<std::string> kPropKeys = {"mesh", "transform", "color", "holdout",
                                            "shadow_catcher"};

void parseTransform(Reader& r, const toml::node& node, const std::string& path, ObjectTransform& xf)
{
    const toml::table* t = r.table(node, path);
    if (!t) return;
    r.checkKeys(*t, path, kTransformKeys);
    if (const toml::node* n = t->get("translate"))
        if (auto v = r.vec3(*n, path + ".translate")) xf.translate = *v;
    if (const toml::node* n = t->get("rotate"))
        if (auto v = r.vec3(*n, path + ".rotate")) xf.rotateRadians = *v * kDegreesToRadians;
    if (const toml::node* n = t->get("scale")) {
        if (n->is_array()) {
            if (auto v = r.positiveVec3(*n, path + ".scale", "a factor")) xf.scale = *v;
        } else if (auto s = r.numberIn(*n, path + ".scale", 0.0, false,
                                       std::numeric_limits<double>::max(),
                                       "a positive factor or an array of 3")) {
            xf.scale = Vec3d(*s);
        }
    }
}

/// A volume file, or a sequence "fx.####.vdb" of which at least one frame is on disk.
void parseVolumeFile(Reader& r, const toml::node& n, const std::string& path,
                     const std::filesystem::path& folder, ObjectSpec& object)
{
    const std::optional<std::string> s = r.string(n, path);
    if (!s || !hasFramePlaceholder(*s)) {
        parseFile(r, n, path, folder, object.volume, object.fileWhere);
        return;
    }
    object.fileWhere = r.at(n);
    const std::filesystem::path p(*s);
    object.volume = p.is_absolute() ? p : folder / p;
    if (const std::string why = checkFramePattern(*s); !why.empty()) {
        r.error(r.at(n), path + ": \"" + *s + "\": " + why);
        return;
    }
    object.volumeFrames = sequenceFrames(object.volume.string());
    if (object.volumeFrames.empty())
        r.error(r.at(n),
                path + ": no file of the sequence '" + *s + "' exists (looked for " +
                    object.volume.string() + ")",
                object.volume.string());
}

/// grids = { density = "...", sdf = "...", color = "..." }: grid names in the volume file.
void parseGridNames(Reader& r, const toml::node& node, const std::string& path,
                    VolumeGridNames& names)
{
    const toml::table* t = r.table(node, path);
    if (!t) return;
    r.checkKeys(*t, path, kGridKeys);
    names.where = r.at(node);
    for (auto [key, name] : {std::pair{"density", &names.density}, std::pair{"sdf", &names.sdf},
                             std::pair{"color", &names.color}})
        if (const toml::node* n = t->get(key))
            if (auto s = r.string(*n, path + "." + key)) {
                if (s->empty()) r.error(r.at(*n), path + "." + key + ": expected a grid name");
                *name = *s;
            }
}

/// window = [lo, hi]: a NIfTI volume's intensities mapped to density 0..1.
void parseWindow(Reader& r, const toml::node& n, const std::string& path, ObjectSpec& object)
{
    if (!isNiftiFile(object.volume)) {
        r.error(r.at(n), path + ": only a NIfTI volume (.nii, .nii.gz) has a window");
        return;
    }
    if (auto w = r.interval(n, path, "the intensities mapped to density 0 and 1", true))
        object.window = *w;
}

/// One [[prop]] table.
PropSpec parseProp(Reader& r, const toml::table& t, const std::string& path,
                   const std::filesystem::path& folder)
{
    r.checkKeys(t, path, kPropKeys);
    PropSpec prop;
    if (const toml::node* n = t.get("mesh"))
        parseFile(r, *n, path + ".mesh", folder, prop.mesh, prop.where);
    else
        r.missing(t, path + ".mesh", "a mesh file name, relative to the scene file");
    if (const toml::node* n = t.get("transform"))
        parseTransform(r, *n, path + ".transform", prop.transform);
    if (const toml::node* n = t.get("color"))
        if (auto c = r.nonNegativeVec3(*n, path + ".color")) {
            if (c->x() > 1.0 || c->y() > 1.0 || c->z() > 1.0)
                r.error(r.at(*n), path + ".color: a reflectance, each channel from 0 to 1");
            prop.color = *c;
        }
    for (auto [key, flag] :
         {std::pair{"holdout", &prop.holdout}, std::pair{"shadow_catcher", &prop.shadowCatcher}})
        if (const toml::node* n = t.get(key))
            if (auto b = r.boolean(*n, path + "." + key)) *flag = *b;
    if (prop.holdout && prop.shadowCatcher)
        r.error(r.at(*t.get("shadow_catcher")),
                path + ": a prop is a holdout or a shadow catcher, not both");
    return prop;
}

} // namespace

void parseObject(Reader& r, const toml::node& node, const std::string& path,
                 const std::filesystem::path& folder, ObjectSpec& object,
                 const std::vector<std::string>& extraKeys)
{
    const toml::table* t = r.table(node, path);
    if (!t) return;
    std::vector<std::string> keys = kObjectKeys;
    keys.insert(keys.end(), extraKeys.begin(), extraKeys.end());
    r.checkKeys(*t, path, keys);
    const toml::node* mesh = t->get("mesh");
    const toml::node* volume = t->get("volume");
    if (mesh && volume)
        r.error(r.at(*volume), path + ": give either mesh or volume, not both");
    else if (mesh)
        parseFile(r, *mesh, path + ".mesh", folder, object.mesh, object.fileWhere);
    else if (volume)
        parseVolumeFile(r, *volume, path + ".volume", folder, object);
    else
        r.missing(node, path + ".mesh",
                  "a mesh file name, or volume = a .vdb file, relative to the scene file");
    if (const toml::node* n = t->get("grids")) {
        if (!volume)
            r.error(r.at(*n),
                    path + ".grids: only a volume has grids (give volume = \"FILE.vdb\")");
        else
            parseGridNames(r, *n, path + ".grids", object.grids);
    }
    if (const toml::node* n = t->get("window")) parseWindow(r, *n, path + ".window", object);
    if (const toml::node* n = t->get("transform"))
        parseTransform(r, *n, path + ".transform", object.transform);
    if (const toml::node* n = t->get("color"))
        if (auto c = r.nonNegativeVec3(*n, path + ".color")) object.color = *c;
}

void parseProps(Reader& r, const toml::node& node, const std::filesystem::path& folder,
                std::vector<PropSpec>& props)
{
    r.eachTable(node, "prop", [&](const toml::table& t, const std::string& path) {
        props.push_back(parseProp(r, t, path, folder));
    });
}

void parseVolume(Reader& r, const toml::node& node, VolumeSpec& volume)
{
    const toml::table* t = r.table(node, "volume");
    if (!t) return;
    r.checkKeys(*t, "volume", kVolumeKeys);
    const toml::node* size = t->get("voxel_size");
    const toml::node* res = t->get("resolution");
    if (size && res) {
        r.error(r.at(*res), "volume: give either voxel_size or resolution, not both");
    } else if (size) {
        volume.voxelSize =
            r.numberIn(*size, "volume.voxel_size", 0.0, false, std::numeric_limits<double>::max(),
                       "a positive length in world units");
    } else if (res) {
        if (auto v = r.integerIn(*res, "volume.resolution", 8, 16384)) volume.resolution = int(*v);
    } else {
        r.missing(node, "volume.voxel_size",
                  "a positive length in world units, or resolution in voxels");
    }
}

} // namespace volmorph::detail
