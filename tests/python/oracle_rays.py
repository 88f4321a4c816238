"""Ray sets and comparison rules for the intersection oracle (test_oracle.py).

Rays are made in float64 and handed to every tracer as the same float32 arrays. The
comparison counts hit/miss and primitive disagreements between a tracer and the
reference (embreex, an independent Embree 4). Where both hit different triangles, the
ray may pass through an edge or vertex they share: that counts as agreement (a tie)
only when, in double precision, the ray genuinely hits both triangles at the same t.
"""
import numpy as np

T_REL = 1e-5            # t agreement where both hit
FLOAT_EPS = 2.0 ** -24  # unit roundoff of float32


def unit(v):
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def random_directions(rng, n):
    while True:
        d = rng.normal(size=(n, 3))
        if (np.linalg.norm(d, axis=1) > 1e-6).all():
            return unit(d)


def random_rays(rng, lo, hi, n):
    """Origins uniform inside the bounds, directions uniform on the sphere."""
    o = lo + (hi - lo) * rng.random((n, 3))
    return o, random_directions(rng, n)


def outside_rays(rng, lo, hi, n):
    """Origins on a sphere around the bounds (outside them); half aimed at a random point
    inside the bounds, half in uniformly random directions."""
    c, r = (lo + hi) / 2, np.linalg.norm(hi - lo)
    o = c + r * random_directions(rng, n)
    target = lo + (hi - lo) * rng.random((n, 3))
    d = np.where((np.arange(n) % 2 == 0)[:, None], unit(target - o), random_directions(rng, n))
    return o, d


def _random_points_on(rng, V, T, tri):
    a, b, c = (V[T[tri, k]] for k in range(3))
    u, v = rng.random(len(tri)), rng.random(len(tri))
    s = np.sqrt(u)
    return a * (1 - s)[:, None] + b * (s * (1 - v))[:, None] + c * (s * v)[:, None], a, b, c


def grazing_rays(rng, V, T, n, extent):
    """Rays through a random point of a random triangle at 1e-5 .. 1e-1 radians to its
    plane (log-uniform), starting 1% .. 50% of the scene's extent before it."""
    tri = rng.integers(0, len(T), n)
    p, a, b, c = _random_points_on(rng, V, T, tri)
    normal = unit(np.cross(b - a, c - a))
    tangent = random_directions(rng, n)
    tangent = unit(tangent - (tangent * normal).sum(1, keepdims=True) * normal)
    angle = 10.0 ** rng.uniform(-5, -1, n)
    side = np.where(rng.random(n) < 0.5, -1.0, 1.0)
    d = np.cos(angle)[:, None] * tangent + (side * np.sin(angle))[:, None] * normal
    o = p - d * (extent * rng.uniform(0.01, 0.5, n))[:, None]
    return o, d


def edge_vertex_rays(rng, V, T, n, lo, hi):
    """Rays aimed exactly at vertices and at points on edges (halfway, a quarter, a third,
    or anywhere along), from origins inside the bounds grown by 10% on each side. The
    target is rounded to float32 as a tracer would store it, and the direction is the
    float32 difference (target at t = 1, direction not unit length)."""
    V32 = V.astype(np.float32)
    tri = rng.integers(0, len(T), n)
    k = rng.integers(0, 3, n)
    a = V32[T[tri, k]]
    b = V32[T[tri, (k + 1) % 3]]
    f = rng.choice(np.array([0.0, 0.5, 0.25, 1.0 / 3.0, -1.0], np.float32), n)
    f = np.where(f < 0, rng.random(n).astype(np.float32), f).astype(np.float32)
    target = (a + (b - a) * f[:, None]).astype(np.float32)
    pad = 0.1 * (hi - lo)
    o = ((lo - pad) + (hi - lo + 2 * pad) * rng.random((n, 3))).astype(np.float32)
    d = (target - o).astype(np.float32)
    keep = np.abs(d).max(1) > 0
    return o[keep], d[keep]


def make_rays(scene, n, seed=0):
    """n rays (about) in four kinds: 40% random inside, 20% from outside, 20% grazing,
    20% at edges and vertices. Returns (origins, directions, kind) with float32 rays."""
    rng = np.random.default_rng(seed)
    V = scene.positions.astype(np.float64)
    T = scene.triangles.astype(np.int64)
    lo, hi = (b.astype(np.float64) for b in scene.bounds)
    extent = float(np.linalg.norm(hi - lo))
    parts = [
        ("random", random_rays(rng, lo, hi, n * 2 // 5)),
        ("outside", outside_rays(rng, lo, hi, n // 5)),
        ("grazing", grazing_rays(rng, V, T, n // 5, extent)),
    ]
    parts.append(("edge_vertex", edge_vertex_rays(rng, V, T, n - sum(len(p[1][0]) for p in parts), lo, hi)))
    o = np.concatenate([p[1][0] for p in parts]).astype(np.float32)
    d = np.concatenate([p[1][1] for p in parts]).astype(np.float32)
    kind = np.concatenate([np.full(len(p[1][0]), i) for i, p in enumerate(parts)])
    # A direction can round to zero only for degenerate input; tracers reject it.
    assert (np.abs(d).max(1) > 0).all()
    return o, d, kind, [p[0] for p in parts]


def double_hit(o, d, tri_vertices, margin=-8.0):
    """Ray against triangle in float64 for rays (k, 3) and triangles (k, 3, 3).
    Returns (hit, t, edge, tol_t): a hit is a point of the plane at t > 0 whose signed
    distance to every edge line (`edge`, the smallest; positive inside) is at least
    margin x tol, where tol = 8 float32 ulps of the largest coordinate involved: the
    inputs themselves carry that rounding, so a ray within tol of an edge hits it for
    all we can tell. tol_t is that tolerance expressed along the ray."""
    o, d = o.astype(np.float64), d.astype(np.float64)
    a, b, c = (tri_vertices[:, k].astype(np.float64) for k in range(3))
    n = np.cross(b - a, c - a)
    nn = np.linalg.norm(n, axis=1)
    with np.errstate(divide="ignore", invalid="ignore"):
        t = ((a - o) * n).sum(1) / (n * d).sum(1)
        p = o + t[:, None] * d
        edge = np.full(len(o), np.inf)
        for u, v in ((a, b), (b, c), (c, a)):
            e = v - u
            edge = np.minimum(edge, (np.cross(e, p - u) * n).sum(1) / (nn * np.linalg.norm(e, axis=1)))
    tol = 8 * FLOAT_EPS * np.maximum(np.abs(o).max(1), np.abs(p).max(1))
    hit = np.isfinite(t) & (t > 0) & (edge >= margin * tol)
    return hit, t, edge / tol, tol / np.linalg.norm(d, axis=1)


def t_tolerance(o, d, tri_vertices, t):
    """max(1e-5, t_condition(...)): the relative t agreement asked of two tracers."""
    return np.maximum(T_REL, t_condition(o, d, tri_vertices, t))


def t_condition(o, d, tri_vertices, t):
    """The relative error in t that float32 input and arithmetic allow: t is a weighted mean of the vertices'
    depths along the ray (Woop et al. 2013), weighted by barycentrics that carry a
    relative error of a few ulps times 1/|cos| of the angle to the normal; an error
    there moves t by up to (largest vertex distance from the origin) / |d|."""
    o, d = o.astype(np.float64), d.astype(np.float64)
    v = tri_vertices.astype(np.float64)
    n = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    dn = np.linalg.norm(d, axis=1)
    cos = np.abs((n * d).sum(1)) / (np.linalg.norm(n, axis=1) * dn)
    reach = np.linalg.norm(v - o[:, None], axis=2).max(1) / dn
    with np.errstate(divide="ignore"):
        return 64 * FLOAT_EPS * reach / (cos * np.abs(t))


class Silhouettes:
    """Whether a ray touches a triangle only at its boundary where the surface does not
    continue across the ray (a silhouette edge or vertex): then hitting and missing are
    both right. Shifts the ray sideways by a few rounding tolerances in 8 directions;
    if any shifted ray misses every triangle around the touched one (the triangles
    sharing one of its vertices), the surface does not cross the ray there. At a shared
    edge or vertex that the ray goes through, every shifted ray hits a neighbour, and a
    miss is a crack."""

    def __init__(self, V, T):
        self.V, self.T = V, T
        flat = T.ravel()
        self.order = np.argsort(flat, kind="stable") // 3
        self.start = np.searchsorted(flat[np.argsort(flat, kind="stable")], np.arange(len(V) + 1))

    def ring(self, tri):
        ids = [self.order[self.start[v]:self.start[v + 1]] for v in self.T[tri]]
        return np.unique(np.concatenate(ids))

    def touches(self, o, d, tri):
        o, d = o.astype(np.float64), d.astype(np.float64)
        hit, t, edge, tol_t = double_hit(o[None], d[None], self.V[self.T[[tri]]])
        if not hit[0] or edge[0] > 1.0:  # hit well inside: not a boundary touch
            return False
        ring = self.ring(tri)
        tris = self.V[self.T[ring]]
        e1 = np.cross(d, [1.0, 0.0, 0.0] if abs(d[0]) < 0.9 * np.linalg.norm(d) else [0.0, 1.0, 0.0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(d, e1)
        e2 /= np.linalg.norm(e2)
        shift = 4 * tol_t[0] * np.linalg.norm(d)
        for phi in np.linspace(0, 2 * np.pi, 8, endpoint=False):
            os_ = o + shift * (np.cos(phi) * e1 + np.sin(phi) * e2)
            h, _, _, _ = double_hit(np.repeat(os_[None], len(ring), 0), np.repeat(d[None], len(ring), 0), tris,
                                    margin=0.0)
            if not h.any():
                return True
        return False


def ill_conditioned_touch(o, d, tri_vertices):
    """The ray meets the triangle so close to parallel that where it crosses the plane is
    uncertain (by t_tolerance along the ray) by more than its distance to the triangle's
    boundary: whether it hits this triangle at all is then not decided by float32 input."""
    hit, t, edge, tol_t = double_hit(o[None], d[None], tri_vertices[None], margin=-np.inf)
    if not np.isfinite(t[0]) or t[0] <= 0:
        return False
    allowed = t_condition(o[None], d[None], tri_vertices[None], t)[0]
    tol = tol_t[0] * np.linalg.norm(d.astype(np.float64))
    return abs(edge[0]) * tol <= allowed * t[0] * np.linalg.norm(d.astype(np.float64)) + tol


def compare(ref, got, o, d, V, T, silhouettes):
    """Counts for one tracer against the reference. ref/got: dicts of hit (bool), prim
    (uint32), t (float32). Agreement: same hit/miss and primitive; or a tie (different
    primitives, both genuinely hit at the same t, in double precision); or a silhouette
    (the nearer answer touches a silhouette edge/vertex, the other hits what lies behind
    or nothing)."""
    hit_miss = ref["hit"] != got["hit"]
    both = ref["hit"] & got["hit"]
    prim_diff = both & (ref["prim"] != got["prim"])
    idx = np.flatnonzero(prim_diff)
    ties = np.zeros(len(o), bool)
    grazing_ties = np.zeros(len(o), bool)
    if len(idx):
        tri_a, tri_b = V[T[ref["prim"][idx].astype(np.int64)]], V[T[got["prim"][idx].astype(np.int64)]]
        ha, ta, _, tol_t = double_hit(o[idx], d[idx], tri_a)
        hb, tb, _, _ = double_hit(o[idx], d[idx], tri_b)
        same_t = np.abs(ta - tb) <= T_REL * np.maximum(np.abs(ta), np.abs(tb)) + tol_t
        ties[idx] = ha & hb & same_t
        # Near-parallel rays: where t is ill-conditioned, so is the point where the ray
        # crosses the plane, and with it which of two neighbours holds it. Widen the
        # edge margin and the t match by what t_tolerance allows.
        cond = np.maximum(t_condition(o[idx], d[idx], tri_a, ta), t_condition(o[idx], d[idx], tri_b, tb))
        margin = -(cond * np.abs(ta) + tol_t) / tol_t
        ga, _, _, _ = double_hit(o[idx], d[idx], tri_a, margin=margin)
        gb, _, _, _ = double_hit(o[idx], d[idx], tri_b, margin=margin)
        close_t = np.abs(ta - tb) <= np.maximum(T_REL, cond) * np.maximum(np.abs(ta), np.abs(tb)) + tol_t
        grazing_ties[idx] = ~ties[idx] & ga & gb & close_t
        ties |= grazing_ties
    # Silhouettes: hit/miss, or different primitives at different t; the nearer answer
    # must be a boundary touch of a silhouette.
    sil = np.zeros(len(o), bool)
    ill = np.zeros(len(o), bool)
    for i in np.flatnonzero(hit_miss | (prim_diff & ~ties)):
        if ref["hit"][i] and (not got["hit"][i] or ref["t"][i] <= got["t"][i]):
            near = int(ref["prim"][i])
        else:
            near = int(got["prim"][i])
        sil[i] = silhouettes.touches(o[i], d[i], near)
        if not sil[i]:
            ill[i] = ill_conditioned_touch(o[i], d[i], V[T[near]])
    # t where both hit the same triangle or a tie within rounding.
    t_pair = both & (~prim_diff | (ties & ~grazing_ties))
    k = np.flatnonzero(t_pair)
    ta, tb = ref["t"][k].astype(np.float64), got["t"][k].astype(np.float64)
    rel = _rel(ta, tb)
    # Each answer's t against the exact t of its own triangle (double precision on the
    # float32 inputs). Where the two differ by more than T_REL, a tracer is charged only
    # if its own t is off the exact one by more than T_REL (the reference can be wrong).
    ref_exact = exact_t_error(ref, o, d, V, T)
    got_exact = exact_t_error(got, o, d, V, T)
    ref_off = ref_exact[k] > T_REL
    got_off = got_exact[k] > T_REL
    t_charged = (rel > T_REL) & got_off
    allowed = t_tolerance(o[k], d[k], V[T[ref["prim"][k].astype(np.int64)]], ta)
    strict = hit_miss | (prim_diff & ~(ties & ~grazing_ties))
    disagree = hit_miss | (prim_diff & ~ties)
    disagree &= ~(sil | ill)
    return {
        "rays": int(len(o)),
        "hits": int(got["hit"].sum()),
        "hit_miss_mismatches": int(hit_miss.sum()),
        "prim_mismatches": int(prim_diff.sum()),
        "ties": int(ties.sum()),
        "ties_ill_conditioned": int(grazing_ties.sum()),
        "silhouettes": int(sil.sum()),
        "ill_conditioned_touches": int(ill.sum()),
        "disagreements": int(disagree.sum()),
        "agreement": float(1.0 - disagree.mean()),
        "agreement_strict": float(1.0 - strict.mean()),
        "t_compared": int(len(k)),
        "t_over_1e-5": int((rel > T_REL).sum()),
        "t_over_1e-5_reference_off": int(((rel > T_REL) & ref_off & ~got_off).sum()),
        "t_over_1e-5_charged": int(t_charged.sum()),
        "t_exact_over_1e-5": int((got_exact > T_REL).sum()),
        "max_t_exact_rel_error": float(got_exact.max()) if got["hit"].any() else 0.0,
        "reference_t_exact_over_1e-5": int((ref_exact > T_REL).sum()),
        "reference_max_t_exact_rel_error": float(ref_exact.max()) if ref["hit"].any() else 0.0,
        "t_over_conditioned": int((rel > allowed).sum()),
        "max_t_rel_error": float(rel.max()) if len(rel) else 0.0,
        "max_t_rel_error_well_conditioned": float(rel[allowed <= T_REL].max()) if (allowed <= T_REL).any() else 0.0,
        "disagree_mask": disagree,
        "strict_mask": strict,
        "t_bad_mask": _scatter(t_pair, rel > allowed),
    }


def exact_t_error(answer, o, d, V, T):
    """Relative error of each hit's t against the exact t (float64, from the float32 ray
    and vertices) of the triangle it names; 0 where it missed."""
    err = np.zeros(len(o))
    h = np.flatnonzero(answer["hit"])
    if len(h):
        _, t_exact, _, _ = double_hit(o[h], d[h], V[T[answer["prim"][h].astype(np.int64)]])
        err[h] = _rel(answer["t"][h].astype(np.float64), t_exact)
    return err


def _rel(a, b):
    return np.abs(a - b) / np.maximum(np.maximum(np.abs(a), np.abs(b)), np.finfo(np.float64).tiny)


def _scatter(mask, values):
    out = np.zeros(len(mask), bool)
    out[mask] = values
    return out
