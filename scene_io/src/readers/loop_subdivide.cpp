// Loop subdivision (C. Loop, "Smooth Subdivision Surfaces Based on Triangles", 1987), for
// the suite's large mesh: a scanned mesh refined at load time (JSON "subdivide": N), so
// the surface stays the scan's (irregular valences, holes) and nothing large is stored.
// Edges are found by sorting half-edges (deterministic, no hash order); an edge with two
// faces is interior, one with one or more than two a crease (boundary rules), and a
// vertex on other than exactly two crease edges stays where it is.
#include <fmt/core.h>

#include <algorithm>
#include <cmath>

#include "pathbench/common/errors.h"
#include "pathbench/common/limits.h"
#include "readers/readers.h"

namespace pb::scene_io {

namespace {

struct Dvec {
  double x = 0, y = 0, z = 0;
  void add(Vec3f p, double w) { x += w * p.x; y += w * p.y; z += w * p.z; }
};

MeshData subdivide_once(const MeshData& in) {
  const size_t nv = in.positions.size(), nf = in.triangles.size();
  // Half-edge k of face f runs v[k] -> v[(k+1)%3]; key: the unordered vertex pair.
  struct Half {
    uint64_t key;
    uint32_t corner;  // 3 f + k
  };
  std::vector<Half> half(3 * nf);
  for (size_t f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = in.triangles[f].v[k], b = in.triangles[f].v[(k + 1) % 3];
      half[3 * f + k] = {(uint64_t(std::min(a, b)) << 32) | std::max(a, b), uint32_t(3 * f + k)};
    }
  std::sort(half.begin(), half.end(), [](const Half& p, const Half& q) {
    return p.key != q.key ? p.key < q.key : p.corner < q.corner;
  });
  // Edges: one per distinct key; edge_of[corner] its id.
  std::vector<uint32_t> edge_of(3 * nf);
  std::vector<uint64_t> edge_key;
  std::vector<uint32_t> edge_faces;  // how many faces share it
  std::vector<Dvec> edge_opposite;   // sum of the vertices opposite it
  for (size_t i = 0; i < half.size(); ++i) {
    if (i == 0 || half[i].key != half[i - 1].key) {
      edge_key.push_back(half[i].key);
      edge_faces.push_back(0);
      edge_opposite.emplace_back();
    }
    const uint32_t e = uint32_t(edge_key.size() - 1), c = half[i].corner;
    edge_of[c] = e;
    ++edge_faces[e];
    edge_opposite[e].add(in.positions[in.triangles[c / 3].v[(c % 3 + 2) % 3]], 1.0);
  }
  half.clear();
  half.shrink_to_fit();
  const size_t ne = edge_key.size();
  if (nv + ne > uint64_t(UINT32_MAX)) throw InputError("subdivision: too many vertices");

  // Old vertices: the sums of their neighbours, all and along creases.
  std::vector<Dvec> ring(nv), crease(nv);
  std::vector<uint32_t> valence(nv, 0), creases(nv, 0);
  for (size_t e = 0; e < ne; ++e) {
    const uint32_t a = uint32_t(edge_key[e] >> 32), b = uint32_t(edge_key[e] & 0xffffffffu);
    ring[a].add(in.positions[b], 1.0);
    ring[b].add(in.positions[a], 1.0);
    ++valence[a];
    ++valence[b];
    if (edge_faces[e] != 2) {
      crease[a].add(in.positions[b], 1.0);
      crease[b].add(in.positions[a], 1.0);
      ++creases[a];
      ++creases[b];
    }
  }
  MeshData out;
  out.positions.resize(nv + ne);
  for (size_t v = 0; v < nv; ++v) {
    const Vec3f p = in.positions[v];
    Dvec q;
    if (valence[v] == 0 || (creases[v] != 0 && creases[v] != 2)) {
      q.add(p, 1.0);
    } else if (creases[v] == 2) {
      q.add(p, 0.75);
      q.x += 0.125 * crease[v].x; q.y += 0.125 * crease[v].y; q.z += 0.125 * crease[v].z;
    } else {
      const double n = valence[v], c = 0.375 + 0.25 * std::cos(2 * M_PI / n);
      const double beta = (0.625 - c * c) / n;
      q.add(p, 1 - n * beta);
      q.x += beta * ring[v].x; q.y += beta * ring[v].y; q.z += beta * ring[v].z;
    }
    out.positions[v] = {float(q.x), float(q.y), float(q.z)};
  }
  for (size_t e = 0; e < ne; ++e) {
    const Vec3f a = in.positions[edge_key[e] >> 32], b = in.positions[edge_key[e] & 0xffffffffu];
    Dvec q;
    if (edge_faces[e] == 2) {
      q.add(a, 0.375);
      q.add(b, 0.375);
      q.x += 0.125 * edge_opposite[e].x; q.y += 0.125 * edge_opposite[e].y; q.z += 0.125 * edge_opposite[e].z;
    } else {
      q.add(a, 0.5);
      q.add(b, 0.5);
    }
    out.positions[nv + e] = {float(q.x), float(q.y), float(q.z)};
  }
  // Four children per face, winding kept: three corners and the middle.
  out.triangles.resize(4 * nf);
  out.material_ids.resize(4 * nf);
  for (size_t f = 0; f < nf; ++f) {
    const uint32_t* v = in.triangles[f].v;
    const uint32_t m0 = uint32_t(nv + edge_of[3 * f]), m1 = uint32_t(nv + edge_of[3 * f + 1]),
                   m2 = uint32_t(nv + edge_of[3 * f + 2]);
    out.triangles[4 * f + 0] = {{v[0], m0, m2}};
    out.triangles[4 * f + 1] = {{v[1], m1, m0}};
    out.triangles[4 * f + 2] = {{v[2], m2, m1}};
    out.triangles[4 * f + 3] = {{m0, m1, m2}};
    const int mat = f < in.material_ids.size() ? in.material_ids[f] : -1;
    for (int k = 0; k < 4; ++k) out.material_ids[4 * f + k] = mat;
  }
  out.materials = in.materials;
  out.material_names = in.material_names;
  return out;
}

}  // namespace

MeshData loop_subdivide(const MeshData& mesh, int levels) {
  if (levels < 0) throw InputError(fmt::format("subdivision: {} levels (expected 0 or more)", levels));
  const uint64_t faces = uint64_t(mesh.triangles.size());
  if (levels > 12 || (faces << (2 * levels)) > limits::kMaxTriangles)
    throw InputError(fmt::format("{} triangles subdivided {} times make {} triangles, more than the supported {}",
                                 faces, levels, levels > 12 ? std::string("too many")
                                                            : std::to_string(faces << (2 * levels)),
                                 limits::kMaxTriangles));
  for (const Triangle& t : mesh.triangles)
    for (uint32_t v : t.v)
      if (v >= mesh.positions.size()) throw InputError("subdivision: a triangle refers to a missing vertex");
  MeshData m = mesh;
  for (int i = 0; i < levels; ++i) m = subdivide_once(m);
  return m;
}

}  // namespace pb::scene_io
