// _volmorph: the compiled half of the Python module `volmorph` (volmorph/__init__.py is the other,
// and the public face). It binds tools/ScriptScene.h and nothing more: a scene, the jobs that
// morph, render and voxelize on a thread of their own, the pairs as dicts, the errors as Python's.
// Grids cross as pyopenvdb objects through the converters `import pyopenvdb` registers with
// Boost.Python (as OpenVDB's own pyopenvdb.h does).
#include "ScriptScene.h"

#include <boost/python.hpp>

#include <cerrno>
#include <memory>
#include <string>

namespace bp = boost::python;

namespace volmorph::script {
namespace {

PyObject* gSceneError = nullptr;       ///< volmorph.SceneError (ValueError)
PyObject* gMissingFileError = nullptr; ///< volmorph.MissingFileError (FileNotFoundError too)

/// UserError as SceneError, or as MissingFileError when one of its problems is a file that does
/// not exist; its text every "file:line:col: message", one per line, and `diagnostics` the same as
/// (file, line, column, message) tuples.
void translateUserError(const UserError& error)
{
    std::string text, missing;
    bp::list diagnostics;
    for (const Diagnostic& d : error.diagnostics()) {
        text += (text.empty() ? "" : "\n") + d.str();
        if (missing.empty()) missing = d.missingFile;
        diagnostics.append(bp::make_tuple(d.where.file, d.where.line, d.where.column, d.message));
    }
    if (text.empty()) text = error.what();
    PyObject* type = missing.empty() ? gSceneError : gMissingFileError;
    bp::object instance =
        missing.empty() ? bp::object(bp::handle<>(PyObject_CallFunction(type, "s", text.c_str())))
                        : bp::object(bp::handle<>(PyObject_CallFunction(
                              type, "iss", ENOENT, text.c_str(), missing.c_str())));
    bp::setattr(instance, "diagnostics", diagnostics);
    PyErr_SetObject(type, instance.ptr());
}

void translateInterrupted(const Interrupted&)
{
    PyErr_SetNone(PyExc_KeyboardInterrupt);
}

void translateFilesystemError(const std::filesystem::filesystem_error& error)
{
    PyErr_SetString(PyExc_OSError, error.what());
}

/// Releases the GIL for its lifetime.
class WithoutGil {
public:
    WithoutGil() : mState(PyEval_SaveThread()) {}
    ~WithoutGil() { PyEval_RestoreThread(mState); }
    WithoutGil(const WithoutGil&) = delete;
    WithoutGil& operator=(const WithoutGil&) = delete;

private:
    PyThreadState* mState;
};

bp::dict gridDict(const openvdb::GridPtrVec& grids)
{
    bp::dict out;
    for (const openvdb::GridBase::Ptr& grid : grids) {
        bp::object value;
        if (auto f = openvdb::gridPtrCast<openvdb::FloatGrid>(grid))
            value = bp::object(f);
        else if (auto v = openvdb::gridPtrCast<openvdb::Vec3SGrid>(grid))
            value = bp::object(v);
        else if (auto b = openvdb::gridPtrCast<openvdb::BoolGrid>(grid))
            value = bp::object(b);
        else
            continue; // a type pyopenvdb does not wrap (volmorph makes none)
        out[grid->getName()] = value;
    }
    return out;
}

/// What a job hands back: grids or an image.
struct JobResult {
    openvdb::GridPtrVec grids;
    render::Image image;
    bool isImage = false;
};

/// A running morph, render or voxelization. The Python side waits on it in short steps (running
/// its signal handlers between them) and cancels it on KeyboardInterrupt.
class PyJob {
public:
    PyJob(bp::object owner, std::function<void(Interrupter&, JobResult&)> work)
        : mOwner(std::move(owner)), mResult(std::make_shared<JobResult>())
    {
        std::shared_ptr<JobResult> result = mResult;
        mJob = std::make_shared<ScriptJob>(
            [work = std::move(work), result](Interrupter& i) { work(i, *result); });
    }

    bool wait(double seconds)
    {
        const WithoutGil unlocked;
        return mJob->wait(seconds);
    }
    void cancel() { mJob->cancel(); }
    std::string stage() const { return mJob->stage(); }
    int percent() const { return mJob->percent(); }
    bool done() { return mJob->wait(0.0); }

    /// After wait() said done: the grids as a dict, or the image as (width, height, bytes of
    /// float32 RGBA, rows from the top); raises what the work raised.
    bp::object result()
    {
        {
            const WithoutGil unlocked;
            mJob->wait(-1.0);
        }
        mJob->rethrow();
        if (!mResult->isImage) return gridDict(mResult->grids);
        const render::Image& image = mResult->image;
        bp::object bytes(bp::handle<>(
            PyByteArray_FromStringAndSize(reinterpret_cast<const char*>(image.pixels.data()),
                                          Py_ssize_t(image.pixels.size() * sizeof(float)))));
        return bp::make_tuple(image.width, image.height, bytes);
    }

    std::weak_ptr<ScriptJob> handle() const { return mJob; }

private:
    bp::object mOwner; ///< keeps the scene alive while the job runs
    std::shared_ptr<JobResult> mResult;
    std::shared_ptr<ScriptJob> mJob;
};

// ---- pairs as dicts ----

bp::tuple vec3(const Vec3d& v)
{
    return bp::make_tuple(v[0], v[1], v[2]);
}

Vec3d vec3(const bp::object& o, const char* what)
{
    if (bp::len(o) != 3) throw std::invalid_argument(std::string(what) + ": expected 3 numbers");
    return Vec3d(bp::extract<double>(o[0]), bp::extract<double>(o[1]), bp::extract<double>(o[2]));
}

bp::dict elementDict(const FeatureElement& e)
{
    bp::dict d;
    d["origin"] = vec3(e.origin);
    d["axes"] = bp::make_tuple(vec3(e.xAxis), vec3(e.yAxis), vec3(e.zAxis));
    d["scale"] = vec3(e.scale);
    return d;
}

FeatureElement elementFrom(const bp::object& d)
{
    FeatureElement e;
    e.origin = vec3(d["origin"], "origin");
    const bp::object axes = d["axes"];
    e.xAxis = vec3(axes[0], "axes[0]");
    e.yAxis = vec3(axes[1], "axes[1]");
    e.zAxis = e.xAxis.cross(e.yAxis);
    e.scale = vec3(d["scale"], "scale");
    return e;
}

FeatureType typeFrom(const std::string& name)
{
    for (FeatureType t :
         {FeatureType::Point, FeatureType::Segment, FeatureType::Rectangle, FeatureType::Box})
        if (name == toString(t)) return t;
    throw std::invalid_argument("type: expected point, segment, rectangle or box, got \"" + name +
                                "\"");
}

// ---- the scene ----

/// The scene and the job running on it (one at a time).
struct PyScene {
    std::shared_ptr<ScriptScene> scene;
    std::weak_ptr<ScriptJob> running;

    void requireIdle() const
    {
        if (const auto job = running.lock(); job && !job->wait(0.0))
            throw std::runtime_error("a morph or render of this scene is running; wait for it "
                                     "or cancel it first");
    }
};

std::shared_ptr<PyScene> openScene(const std::string& path)
{
    auto s = std::make_shared<PyScene>();
    s->scene = std::make_shared<ScriptScene>(path);
    return s;
}

GridNames namesFrom(const std::string& preset)
{
    if (preset == "volmorph") return GridNames::Volmorph;
    if (preset == "houdini") return GridNames::Houdini;
    if (preset == "blender") return GridNames::Blender;
    throw std::invalid_argument("names: expected volmorph, houdini or blender, got \"" + preset +
                                "\"");
}

std::shared_ptr<PyJob> startMorph(bp::object self, int frame, const std::string& preset,
                                  const std::string& file)
{
    PyScene& s = bp::extract<PyScene&>(self);
    s.requireIdle();
    const GridNames names = namesFrom(preset);
    std::shared_ptr<ScriptScene> scene = s.scene;
    auto job =
        std::make_shared<PyJob>(self, [scene, frame, names, file](Interrupter& i, JobResult& r) {
            r.grids = scene->morph(frame, names, file, i);
        });
    s.running = job->handle();
    return job;
}

std::shared_ptr<PyJob> startRender(bp::object self, int frame, const std::string& file)
{
    PyScene& s = bp::extract<PyScene&>(self);
    s.requireIdle();
    std::shared_ptr<ScriptScene> scene = s.scene;
    auto job = std::make_shared<PyJob>(self, [scene, frame, file](Interrupter& i, JobResult& r) {
        r.image = scene->render(frame, file, i);
        r.isImage = true;
    });
    s.running = job->handle();
    return job;
}

std::shared_ptr<PyJob> startVoxelize(const std::string& mesh, bp::object voxelSize,
                                     bp::object resolution)
{
    std::optional<double> size;
    std::optional<int> across;
    if (!voxelSize.is_none()) size = bp::extract<double>(voxelSize);
    if (!resolution.is_none()) across = bp::extract<int>(resolution);
    return std::make_shared<PyJob>(bp::object(),
                                   [mesh, size, across](Interrupter& i, JobResult& r) {
                                       r.grids = voxelizeMesh(mesh, size, across, i);
                                   });
}

bp::list frames(const PyScene& s)
{
    bp::list out;
    for (int f : s.scene->frames()) out.append(f);
    return out;
}

bp::list pairs(const PyScene& s)
{
    bp::list out;
    for (const Pair& p : s.scene->pairs()) {
        bp::dict d;
        d["type"] = std::string(toString(p.type));
        d["source"] = elementDict(p.source);
        d["target"] = elementDict(p.target);
        out.append(d);
    }
    return out;
}

void setPairs(PyScene& s, const bp::list& list)
{
    s.requireIdle();
    std::vector<Pair> pairs;
    for (bp::ssize_t i = 0; i < bp::len(list); ++i) {
        const bp::object d = list[i];
        Pair p;
        p.type = typeFrom(bp::extract<std::string>(d["type"]));
        p.source = elementFrom(d["source"]);
        p.target = elementFrom(d["target"]);
        pairs.push_back(p);
    }
    s.scene->setPairs(pairs);
}

void save(PyScene& s, const std::string& file)
{
    s.requireIdle();
    s.scene->save(file);
}

/// A mesh as (points: bytes of float32 x y z, triangles: bytes of uint32 a b c), or None.
bp::object meshTuple(const Mesh& mesh)
{
    if (mesh.points.empty()) return bp::object();
    auto bytes = [](const void* data, size_t size) {
        return bp::object(bp::handle<>(
            PyByteArray_FromStringAndSize(static_cast<const char*>(data), Py_ssize_t(size))));
    };
    static_assert(sizeof(Vec3f) == 12 && sizeof(Vec3I) == 12, "packed vectors");
    return bp::make_tuple(bytes(mesh.points.data(), mesh.points.size() * sizeof(Vec3f)),
                          bytes(mesh.triangles.data(), mesh.triangles.size() * sizeof(Vec3I)));
}

bp::dict sideMeshes(const PyScene& s)
{
    SceneMeshes meshes;
    {
        const WithoutGil unlocked;
        meshes = s.scene->sideMeshes();
    }
    bp::dict out;
    out["source"] = meshTuple(meshes.source);
    out["target"] = meshTuple(meshes.target);
    return out;
}

bp::dict medium(const PyScene& s)
{
    const RenderSpec& r = s.scene->scene().render;
    bp::dict out;
    out["extinction"] = r.extinction;
    out["albedo"] = r.albedo;
    out["anisotropy"] = r.anisotropy;
    out["emission"] = vec3(r.emission);
    out["fps"] = s.scene->scene().frames.fps;
    return out;
}

std::string path(const PyScene& s)
{
    return s.scene->path().string();
}

std::string text(const PyScene& s)
{
    return s.scene->text();
}

void defineErrors()
{
    gSceneError = PyErr_NewException("volmorph.SceneError", PyExc_ValueError, nullptr);
    bp::handle<> bases(PyTuple_Pack(2, PyExc_FileNotFoundError, gSceneError));
    gMissingFileError = PyErr_NewException("volmorph.MissingFileError", bases.get(), nullptr);
    bp::scope().attr("SceneError") = bp::handle<>(bp::borrowed(gSceneError));
    bp::scope().attr("MissingFileError") = bp::handle<>(bp::borrowed(gMissingFileError));
    bp::register_exception_translator<UserError>(translateUserError);
    bp::register_exception_translator<Interrupted>(translateInterrupted);
    bp::register_exception_translator<std::filesystem::filesystem_error>(translateFilesystemError);
}

} // namespace
} // namespace volmorph::script

BOOST_PYTHON_MODULE(_volmorph)
{
    using namespace volmorph::script;
    openvdb::initialize();
    defineErrors();
    bp::class_<PyJob, std::shared_ptr<PyJob>, boost::noncopyable>("Job", bp::no_init)
        .def("wait", &PyJob::wait)
        .def("cancel", &PyJob::cancel)
        .def("done", &PyJob::done)
        .def("stage", &PyJob::stage)
        .def("percent", &PyJob::percent)
        .def("result", &PyJob::result);
    bp::class_<PyScene, std::shared_ptr<PyScene>, boost::noncopyable>("Scene", bp::no_init)
        .def("__init__", bp::make_constructor(&openScene))
        .def("path", &path)
        .def("frames", &frames)
        .def("pairs", &pairs)
        .def("set_pairs", &setPairs)
        .def("text", &text)
        .def("side_meshes", &sideMeshes)
        .def("medium", &medium)
        .def("save", &save)
        .def("start_morph", &startMorph)
        .def("start_render", &startRender);
    bp::def("start_voxelize", &startVoxelize);
}
