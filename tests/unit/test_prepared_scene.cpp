// run::PreparedScene (prepared.h: the suite's benchmarks, issue 28): a scene built once renders
// frames that are run::render's for the same settings (film bit for bit, rays, report fields),
// frame after frame and for other frame settings it serves; settings that need another build
// are refused, and bad settings before anything is built.
#include <gtest/gtest.h>

#include <stdexcept>

#include "pathbench/common/errors.h"
#include "pathbench/common/scene_library.h"
#include "pathbench/run/prepared.h"
#include "pathbench/run/run.h"

namespace pb {
namespace {

RenderSettings tiny() {
  RenderSettings s;
  s.width = 12;
  s.height = 8;
  s.spp = 4;
  s.threads = 1;
  s.progress = false;
  s.embree_layout = EmbreeLayout::Triangles;
  return s;
}

TEST(PreparedScene, FramesAreRendersWithoutTheBuild) {
  const Scene scene = make_paper_cornell();
  const RenderSettings s = tiny();
  const run::PreparedScene prepared(scene, s);
  EXPECT_GE(prepared.build_seconds(), 0.0);
  const run::Rendered want = run::render(scene, s);
  Film film;
  for (int frame = 0; frame < 2; ++frame) {
    RunReport r;
    prepared.render(s, film, r);
    EXPECT_EQ(film.raw_sums(), want.film.raw_sums());
    EXPECT_EQ(r.extra["film_hash"], want.report.extra["film_hash"]);
    EXPECT_EQ(r.rays.total(), want.report.rays.total());
    EXPECT_EQ(r.scene, scene.name);
    EXPECT_EQ(r.triangles, scene.triangles.size());
  }
  // Another frame size, sample count and sampling on the same structure.
  RenderSettings other = s;
  other.width = 16;
  other.spp = 2;
  other.sampling = Sampling::Uniform;
  ASSERT_TRUE(prepared.serves(other));
  RunReport r;
  prepared.render(other, film, r);
  EXPECT_EQ(film.width(), 16u);
  EXPECT_EQ(film.raw_sums(), run::render(scene, other).film.raw_sums());
  // A structure of another kind is not there.
  RenderSettings quads = s;
  quads.embree_layout = EmbreeLayout::Quads;
  EXPECT_FALSE(prepared.serves(quads));
  EXPECT_THROW(prepared.render(quads, film, r), std::logic_error);
}

TEST(PreparedScene, RefusesBadSettingsBeforeBuilding) {
  const Scene scene = make_paper_cornell();
  RenderSettings s = tiny();
  s.spp = 0;
  EXPECT_THROW(run::PreparedScene(scene, s), InputError);
}

}  // namespace
}  // namespace pb
