// What `volmorph edit` serves, without the HTTP: the scene being edited (EditDocument), its two
// sides voxelized once at a preview resolution, and a Morpher kept across edits (its blend setup
// shared through Morpher::withPairs), so that after a drag only the in-between at t and its
// surface are made anew. A surface-mode scene (blend.mode = "surface") shows its two meshes as
// they are and its in-between mesh (SurfaceMorph.h); its pairs are landmarks, and an edit of them
// puts the meshes into correspondence anew at the next in-between (a landmark the correspondence
// refuses: 409 with its message). handle() answers the page's JSON API; the server (EditorServer.h)
// adds the token, the size bounds and the page's files.
//
// The document is held under one lock for as long as a request reads or edits it, never while an
// in-between is morphed: a morph takes a copy of the pairs and settings under the lock, runs
// without it (one morph at a time), and stores its mesh only if the pairs have not changed
// meanwhile. So a save or an edit is answered during a slow frame, and the morph stops (503) when
// the session's interrupter asks (SIGINT, SIGTERM).
//
// API (every answer JSON but the meshes'; an error is {"error": message}: 400 for a malformed or
// refused request, 404 for no such call, 405 for a method other than GET and POST, 409 for an edit
// that conflicts (undo with nothing to undo), 500 when the scene file cannot be written or the
// morph fails, 503 when the editor is stopping):
//   GET  /api/state                       EditDocument::state()
//   GET  /api/mesh?of=source|target       a side's surface (encodeMesh)
//   GET  /api/mesh?of=morph&t=T           the in-between's surface at t in [0, 1], with each
//                                         vertex's delay under a timing (the page's colours)
//   POST /api/set|add|duplicate|delete|undo|redo   an edit (EditDocument::apply); the new state
//   POST /api/suggest                     `pairs suggest`'s pairs appended; the new state (400
//                                         in surface mode: landmarks are placed by hand)
//   POST /api/save                        the scene written in place; the new state
#pragma once

#include "EditDocument.h"

#include <volmorph/Morph.h>
#include <volmorph/SurfaceMorph.h>

#include <openvdb/openvdb.h>

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

namespace volmorph {
class Interrupter;
}

namespace volmorph::editor {

struct Reply {
    int status = 200;
    std::string type = "application/json";
    std::string body;
};

/// A surface for the page, compact: "VMM1", the vertex and triangle counts (uint32), the bounding
/// box (6 float32, world units), each vertex's position quantized to uint16 over the box (a
/// 65535th of it: far below a voxel), zero padding to 4 bytes, then the triangles (3 uint32
/// each). Little-endian. A quad is two triangles. With `delays` (one per vertex: the timing's
/// delay there, in t), "VMM2", and the delays as float32 after the triangles.
std::string encodeMesh(const std::vector<openvdb::Vec3s>& points,
                       const std::vector<openvdb::Vec3I>& triangles,
                       const std::vector<openvdb::Vec4I>& quads,
                       const std::vector<float>* delays = nullptr);

/// The surface of a side or an in-between: the sdf's zero level set, or the density's 0.5 level
/// where it has no sdf (a fog volume), by OpenVDB's volumeToMesh; encoded, with each vertex's
/// delay under `timing` when it is active.
std::string surfaceOf(const VolumeSet& volumes, const LocalTime* timing = nullptr);

/// A mesh (world units, triangles wound as the file has them) encoded as above, with each vertex's
/// delay under `timing` when it is active.
std::string encodeTriangles(const std::vector<Vec3d>& points, const std::vector<Vec3I>& triangles,
                            const LocalTime* timing = nullptr);

class EditorSession {
public:
    /// Reads the scene (UserError when it is not valid) and voxelizes both sides at `resolution`
    /// voxels across (the scene's own voxel size when that is coarser). Stops with Interrupted;
    /// later, `interrupter` stops the in-betweens' morphs too (it must outlive the session).
    EditorSession(const std::filesystem::path& scene, int resolution, Interrupter* interrupter);
    ~EditorSession();

    /// Answers one API request; `query` holds the URL's parameters. Thread-safe: one request at a
    /// time. Never throws for what a request holds.
    Reply handle(const std::string& method, const std::string& route,
                 const std::map<std::string, std::string>& query, const std::string& body);

    const EditDocument& document() const { return mDocument; }

private:
    Reply route(const std::string& method, const std::string& route, const std::string& body);
    Reply sideMesh(const std::map<std::string, std::string>& query);
    /// The in-between's mesh at t, morphed outside mMutex (see the top of this file).
    Reply morphMesh(double t);
    /// The same in surface mode: the in-between mesh of the pairs' correspondence.
    Reply surfaceMesh(double t);
    /// Stores the in-between's mesh of version `version` (pairs and timing) at t (under mMutex).
    void keepMorphMesh(const std::string& mesh, uint64_t version, double t);

    std::mutex mMutex;      ///< the document and the caches below
    std::mutex mMorphMutex; ///< one morph at a time
    Interrupter* mInterrupter;
    EditDocument mDocument;
    // Set once by the constructor, read without a lock afterwards.
    VolumeSet mSource, mTarget;
    std::vector<TimedVolume> mInfluences;               ///< variational mode's
    std::vector<TimingRegion> mTimingRegions;           ///< the timing's regions, read once
    std::optional<std::pair<Mesh, Mesh>> mSurfaceSides; ///< surface mode's meshes, placed
    std::string mSourceMesh, mTargetMesh;
    /// The last Morpher, for the pairs of version mMorpherVersion and the timing of version
    /// mMorpherTiming (its blend setup is reused), and that timing (null: none).
    std::shared_ptr<const Morpher> mMorpher;
    std::shared_ptr<const LocalTime> mLocalTime;
    uint64_t mMorpherVersion = 0, mMorpherTiming = 0;
    /// Surface mode: the correspondence of the pairs of version mSurfaceVersion.
    std::shared_ptr<const SurfaceMorpher> mSurfaceMorpher;
    uint64_t mSurfaceVersion = ~uint64_t(0);
    /// The last in-between's mesh, by the pairs' version and t.
    std::string mMorphMesh;
    uint64_t mMorphVersion = ~uint64_t(0);
    double mMorphT = -1.0;
};

} // namespace volmorph::editor
