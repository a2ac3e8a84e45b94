// NIfTI scans as volume inputs: a phantom (a sphere of one intensity inside a box of another,
// written with libnifti2) windowed to the sphere, placed by its sform and the side's scale, and
// morphed into a mesh.
#include "support/VolumeFixtures.h"

#include <volmorph/SceneVolumes.h>
#include <volmorph/VolumeInput.h>

#include <nifti2_io.h>

using namespace volmorph;
using namespace volmorph::test;
using volmorph::test::cloud::clouds;

namespace {

constexpr int kN = 64;            ///< voxels along each axis
constexpr double kSpacing = 2.0;  ///< millimetres
constexpr double kRadius = 20.0;  ///< voxels: the sphere of intensity 1000
constexpr double kBoxHalf = 28.0; ///< voxels: the box of intensity 300 around it

/// Writes the phantom as a gzipped NIfTI-1 file, int16, its sform centring it on the origin.
std::filesystem::path writePhantom()
{
    const std::filesystem::path file = clouds().dir / "phantom.nii.gz";
    const int64_t dims[8] = {3, kN, kN, kN, 1, 1, 1, 1};
    nifti_image* nim = nifti_make_new_nim(dims, DT_INT16, /*data_fill=*/1);
    int16_t* data = static_cast<int16_t*>(nim->data);
    const double c = (kN - 1) / 2.0;
    for (int k = 0; k < kN; ++k)
        for (int j = 0; j < kN; ++j)
            for (int i = 0; i < kN; ++i) {
                const double x = i - c, y = j - c, z = k - c;
                const bool ball = x * x + y * y + z * z <= kRadius * kRadius;
                const bool box = std::max({std::abs(x), std::abs(y), std::abs(z)}) <= kBoxHalf;
                data[(size_t(k) * kN + j) * kN + i] = int16_t(ball ? 1000 : box ? 300 : 0);
            }
    nim->dx = nim->dy = nim->dz = nim->pixdim[1] = nim->pixdim[2] = nim->pixdim[3] = kSpacing;
    nim->sform_code = 1;
    for (int r = 0; r < 4; ++r)
        for (int col = 0; col < 4; ++col) nim->sto_xyz.m[r][col] = 0.0;
    for (int a = 0; a < 3; ++a) {
        nim->sto_xyz.m[a][a] = kSpacing;
        nim->sto_xyz.m[a][3] = -c * kSpacing;
    }
    nim->sto_xyz.m[3][3] = 1.0;
    nifti_set_filenames(nim, file.string().c_str(), 0, 1);
    nifti_image_write(nim);
    nifti_image_free(nim);
    return file;
}

/// The phantom in world units of metres (scale 0.001): voxels of 2 mm = 0.002.
VolumeSource phantom(std::optional<std::pair<double, double>> window)
{
    static const std::filesystem::path file = writePhantom();
    VolumeSource spec;
    spec.file = file;
    spec.window = window;
    spec.transform.scale = Vec3d(0.001);
    return spec;
}

} // namespace

TEST(Nifti, APhantomWindowedToItsSphereIsTheSphere)
{
    const VolumeInput input(phantom(std::pair{600.0, 1000.0}));
    EXPECT_NEAR(input.info().voxelSize, 0.002, 1e-12);
    EXPECT_EQ(input.info().density, "density");
    VolumeInputOptions o;
    o.voxelSize = 0.002;
    const VolumeSet v = input.resample(o);
    // The window maps the box (300) to 0 and the sphere (1000) to 1: the density is the sphere,
    // centred on the origin by the sform, of volume 4/3 pi r^3.
    const Moments m = moments(*v.density);
    const double r = kRadius * 0.002;
    EXPECT_NEAR(m.mass * std::pow(0.002, 3) / (4.0 / 3.0 * M_PI * r * r * r), 1.0, 0.02);
    EXPECT_NEAR(m.centroid.length(), 0.0, 0.05 * 0.002);
    for (auto it = v.density->cbeginValueOn(); it; ++it)
        EXPECT_LE(v.density->indexToWorld(it.getCoord()).length(), r + 0.002);
    // Unwindowed (the intensities' range 0..1000), the box is there at 0.3.
    const VolumeSet whole = VolumeInput(phantom(std::nullopt)).resample(o);
    EXPECT_NEAR(whole.density->tree().getValue(whole.density->transform().worldToIndexCellCentered(
                    Vec3d(0.0, 0.0, 0.024 * 2.0))),
                0.3f, 1e-6);
}

TEST(Nifti, APhantomMorphsIntoAMesh)
{
    const std::string text = "[source]\nvolume = \"" + phantom(std::nullopt).file.string() +
                             "\"\nwindow = [600, 1000]\ntransform = { scale = 0.001 }\n"
                             "[target]\nmesh = \"" +
                             (kMeshes / "cube.obj").string() +
                             "\"\ntransform = { scale = 0.06, translate = [0.1, 0, 0] }\n"
                             "[[pair]]\ntype = \"point\"\n"
                             "source = { origin = [0, 0, 0] }\ntarget = { origin = [0.1, 0, 0] }\n"
                             "[frames]\nrange = \"0-2\"\noutput = \"o.####.exr\"\n";
    const Scene scene = parseScene(text, clouds().dir / "nifti.toml");
    const SceneVolumes v = voxelizeScene(scene);
    EXPECT_NEAR(v.source.voxelSize(), 0.002, 1e-12); // no [volume]: the scan's voxels
    const Morpher morpher(v.source, v.target, scene.pairs, scene.warp, scene.blend);
    // A point pair translates: halfway, the mass centre is halfway (both are centred on their
    // origins), and the mass is the mean of the two.
    const Moments s = moments(*v.source.density), t = moments(*v.target.density);
    const Moments h = moments(*morpher.frame(0.5).density);
    EXPECT_NEAR(h.mass / (0.5 * (s.mass + t.mass)), 1.0, 0.01);
    EXPECT_NEAR(h.centroid.x(), 0.05, 0.1 * 0.002);
}
