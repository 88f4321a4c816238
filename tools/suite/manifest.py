"""The suite's manifest (scenes/suite/manifest.json): loaded, validated, filtered.

Bad input raises ManifestError with one line naming the file and the field; the command
turns it into exit status 2. A workload whose required mesh is missing is not an error:
it is returned as skipped, with the package and workload named."""
from __future__ import annotations

import hashlib
import json
import os
import re

SETTINGS = {"width", "height", "spp", "bounces", "sampling", "strategy", "isa", "instancing", "precision",
            "embree_layout", "seed", "converged"}
INT_SETTINGS = {"width": 1, "height": 1, "spp": 1, "bounces": 0, "seed": 0}
CHOICES = {"sampling": {"uniform", "cosine", "nee"}, "strategy": {"pixel", "wavefront", "paper-queue"},
           "isa": {"auto", "avx512", "avx2", "scalar"}, "instancing": {"auto", "on", "off"},
           "precision": {"float", "double"}, "embree_layout": {"auto", "triangles", "quads"}}
WORKLOAD_KEYS = {"name", "scene", "stresses", "triangles", "instanced_triangles", "materials", "licence",
                 "requires", "settings", "quick", "quick_scene"}
# quick_scene: the scene --quick renders instead (same camera and materials, fewer triangles).
OPTIONAL_KEYS = {"requires", "quick", "quick_scene", "instanced_triangles", "description", "notes"}
SCENE_EXTENSIONS = (".json", ".obj", ".ply", ".gltf", ".glb", ".xml", ".off")
NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]{0,63}$")


class ManifestError(ValueError):
    pass


def data_dir() -> str:
    """$PATHBENCH_DATA_DIR, else ${XDG_DATA_HOME:-~/.local/share}/pathbench/data."""
    env = os.environ.get("PATHBENCH_DATA_DIR")
    if env:
        return env
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local", "share")
    return os.path.join(base, "pathbench", "data")


def _settings(path: str, where: str, s, partial: bool) -> dict:
    if not isinstance(s, dict):
        raise ManifestError(f"{path}: {where}: must be an object of `pathbench render` options")
    out = {}
    for k, v in s.items():
        key = k.replace("-", "_")
        if key not in SETTINGS:
            raise ManifestError(f"{path}: {where}.{k}: unknown setting (known: {', '.join(sorted(SETTINGS))})")
        if key in INT_SETTINGS:
            if isinstance(v, bool) or not isinstance(v, int) or v < INT_SETTINGS[key] or v > 2 ** 31:
                raise ManifestError(f"{path}: {where}.{k}: must be an integer >= {INT_SETTINGS[key]}")
        elif key == "converged":
            if not isinstance(v, bool):
                raise ManifestError(f"{path}: {where}.{k}: must be true or false")
        elif not isinstance(v, str) or v not in CHOICES[key]:
            raise ManifestError(f"{path}: {where}.{k}: must be one of {', '.join(sorted(CHOICES[key]))}")
        out[key] = v
    if not partial:
        for k in ("width", "height", "spp"):
            if k not in out:
                raise ManifestError(f"{path}: {where}: '{k}' is missing")
    return out


def _workload(path: str, i: int, w) -> dict:
    where = f"workloads[{i}]"
    if not isinstance(w, dict):
        raise ManifestError(f"{path}: {where}: must be an object")
    name = w.get("name")
    if not isinstance(name, str) or not NAME.match(name):
        raise ManifestError(f"{path}: {where}.name: must be a name of letters, digits and . _ + - (got {name!r})")
    where = f"workloads[{i}] ({name})"
    for k in w:
        if k not in WORKLOAD_KEYS | OPTIONAL_KEYS:
            raise ManifestError(f"{path}: {where}.{k}: unknown field")
    for k in ("scene", "stresses", "triangles", "materials", "licence", "settings"):
        if k not in w:
            raise ManifestError(f"{path}: {where}.{k}: missing")
    for k in ("scene", "stresses", "licence"):
        if not isinstance(w[k], str) or not w[k]:
            raise ManifestError(f"{path}: {where}.{k}: must be a non-empty string")
    for k in ("triangles", "instanced_triangles"):
        v = w.get(k, 0)
        if isinstance(v, bool) or not isinstance(v, int) or v < 0:
            raise ManifestError(f"{path}: {where}.{k}: must be an integer >= 0")
    if not isinstance(w["materials"], list) or not all(isinstance(m, str) for m in w["materials"]):
        raise ManifestError(f"{path}: {where}.materials: must be a list of strings")
    requires = w.get("requires", [])
    if not isinstance(requires, list):
        raise ManifestError(f"{path}: {where}.requires: must be a list of {{package, file}}")
    for j, r in enumerate(requires):
        if (not isinstance(r, dict) or not {"package", "file"} <= set(r) <= {"package", "file", "sha256"}
                or not all(isinstance(v, str) and v for v in r.values())
                or os.path.isabs(r["file"]) or ".." in r["file"].split("/")
                or ("sha256" in r and not re.fullmatch(r"[0-9a-f]{64}", r["sha256"]))):
            raise ManifestError(f"{path}: {where}.requires[{j}]: must be {{\"package\": NAME, \"file\": RELATIVE PATH"
                                f"[, \"sha256\": 64 hex digits]}}")
    settings = _settings(path, f"{where}.settings", w["settings"], partial=False)
    quick = _settings(path, f"{where}.quick", w.get("quick", {}), partial=True)
    scene = _scene(path, where, "scene", w["scene"])
    quick_scene = _scene(path, where, "quick_scene", w["quick_scene"]) if "quick_scene" in w else scene
    return {"name": name, "scene": scene, "quick_scene": quick_scene, "scene_field": w["scene"], "stresses": w["stresses"],
            "triangles": w["triangles"], "instanced_triangles": w.get("instanced_triangles", 0),
            "materials": w["materials"], "licence": w["licence"], "requires": requires,
            "settings": settings, "quick": quick}


def _scene(path: str, where: str, key: str, scene) -> str:
    """A built-in name as it is; a scene file as an absolute path (relative to the manifest)."""
    if not isinstance(scene, str) or not scene:
        raise ManifestError(f"{path}: {where}.{key}: must be a non-empty string")
    if scene.lower().endswith(SCENE_EXTENSIONS):
        full = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(path)), scene))
        if not os.path.isfile(full):
            raise ManifestError(f"{path}: {where}.{key}: {scene}: no such file (paths are relative to the manifest)")
        return full
    return scene


def load(path: str) -> dict:
    """The manifest as {suite, version, sha256, path, workloads: [...]}; ManifestError on bad input."""
    try:
        with open(path, "rb") as f:
            raw = f.read(16 * 1024 * 1024 + 1)
    except OSError as e:
        raise ManifestError(f"{path}: cannot read the manifest: {e.strerror}") from None
    if len(raw) > 16 * 1024 * 1024:
        raise ManifestError(f"{path}: larger than 16 MiB: not a manifest")
    try:
        doc = json.loads(raw.decode("utf-8"), parse_constant=lambda c: (_ for _ in ()).throw(ValueError(f"{c} is not JSON")))
    except (UnicodeDecodeError, ValueError, RecursionError) as e:
        raise ManifestError(f"{path}: not valid JSON ({str(e).splitlines()[0]})") from None
    if not isinstance(doc, dict):
        raise ManifestError(f"{path}: must be a JSON object with suite, version and workloads")
    if doc.get("suite") != "pathbench":
        raise ManifestError(f"{path}: suite: must be \"pathbench\" (got {doc.get('suite')!r})")
    v = doc.get("version")
    if isinstance(v, bool) or not isinstance(v, int) or v < 1:
        raise ManifestError(f"{path}: version: must be an integer >= 1")
    ws = doc.get("workloads")
    if not isinstance(ws, list) or not ws:
        raise ManifestError(f"{path}: workloads: must be a non-empty list")
    workloads, seen = [], set()
    for i, w in enumerate(ws):
        wl = _workload(path, i, w)
        if wl["name"] in seen:
            raise ManifestError(f"{path}: workloads[{i}].name: '{wl['name']}' appears twice")
        seen.add(wl["name"])
        workloads.append(wl)
    return {"suite": "pathbench", "version": v, "path": path, "sha256": hashlib.sha256(raw).hexdigest(),
            "workloads": workloads}


def select(manifest: dict, pattern: str | None) -> list[dict]:
    """The workloads whose name matches `pattern` (re.search); ManifestError when it is not a
    regular expression or matches none."""
    if not pattern:
        return list(manifest["workloads"])
    try:
        rx = re.compile(pattern)
    except re.error as e:
        raise ManifestError(f"--workloads: not a regular expression: {e}") from None
    chosen = [w for w in manifest["workloads"] if rx.search(w["name"])]
    if not chosen:
        names = ", ".join(w["name"] for w in manifest["workloads"])
        raise ManifestError(f"--workloads: '{pattern}' matches no workload of {manifest['path']} ({names})")
    return chosen


def missing_requirement(workload: dict, data: str) -> str | None:
    """Why the workload cannot run here (a required mesh missing or empty), or None."""
    for r in workload["requires"]:
        f = os.path.join(data, "meshes", r["file"])
        if not os.path.isfile(f):
            return (f"needs {r['file']} from the Debian package {r['package']} (not in {os.path.join(data, 'meshes')}; "
                    f"install it with scripts/install-deps.sh or set PATHBENCH_DATA_DIR)")
        if os.path.getsize(f) == 0:
            return f"{f} (package {r['package']}) is empty: reinstall it with scripts/install-deps.sh"
        if "sha256" in r and _sha256(f) != r["sha256"]:
            return (f"{f} (package {r['package']}) is not the file the suite was made with (its SHA-256 differs: "
                    f"truncated, or another version): reinstall it with scripts/install-deps.sh")
    return None


_SHA_CACHE: dict = {}


def _sha256(f: str) -> str:
    key = (f, os.path.getsize(f), os.path.getmtime(f))
    if key not in _SHA_CACHE:
        h = hashlib.sha256()
        with open(f, "rb") as fh:
            for block in iter(lambda: fh.read(1 << 20), b""):
                h.update(block)
        _SHA_CACHE[key] = h.hexdigest()
    return _SHA_CACHE[key]


def _off_faces(f: str) -> int:
    """The face count in an OFF file's header (0 when unreadable)."""
    try:
        with open(f, "rb") as fh:
            words = []
            for line in fh:
                line = line.split(b"#")[0].strip()
                if not line:
                    continue
                words += line.split()
                if len(words) >= 4:
                    break
        w = words[1:] if words[0].upper().endswith(b"OFF") else words
        return int(w[1])
    except (OSError, ValueError, IndexError):
        return 0


def triangle_estimate(workload: dict, data: str, quick: bool) -> tuple[int, int]:
    """(flat, instanced) triangles of a frame: the manifest's counts, else (0 there) the JSON
    scene's meshes from the data folder (OFF headers, x4 per Loop subdivision level, x the
    number of "instances") plus its triangles."""
    flat, inst = workload["triangles"], workload["instanced_triangles"]
    if flat > 0 or inst > 0:
        return flat, inst
    scene = workload["quick_scene"] if quick else workload["scene"]
    if not scene.endswith(".json") or not os.path.isfile(scene) or os.path.getsize(scene) > 64 << 20:
        return 0, 0
    try:
        with open(scene) as fh:
            doc = json.load(fh)
        for m in doc.get("meshes", []) if isinstance(doc, dict) else []:
            f = m.get("file", "") if isinstance(m, dict) else ""
            if isinstance(f, str) and f.startswith("data:"):
                faces = _off_faces(os.path.join(data, f[len("data:"):])) * 4 ** int(m.get("subdivide", 0) or 0)
                if isinstance(m.get("instances"), list):
                    inst += faces * len(m["instances"])
                else:
                    flat += faces
        return flat, inst
    except (OSError, ValueError, TypeError, AttributeError):
        return 0, 0


def scene_of(workload: dict, quick: bool) -> str:
    return workload["quick_scene"] if quick else workload["scene"]


def run_settings(workload: dict, quick: bool) -> dict:
    s = dict(workload["settings"])
    if quick:
        s.update(workload["quick"])
    return s
