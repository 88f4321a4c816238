"""pathbench: scenes as numpy arrays, batched ray casts (the CPU tracer's Embree scene or
the GPU BVH's traversal on the host) and renders, from the C++ extension `_core`.

Thread safety: any number of threads may call in at once (the work runs with the GIL
released); a Scene builds its acceleration structures once, on first use, under a lock.
Types: __init__.pyi (checked by tests/python/test_package.py).
"""
from ._core import (NO_HIT, Scene, __version__, builtin_scenes, export_mitsuba, git_revision, gpu_available,
                    load_scene, render)

__all__ = ["NO_HIT", "Scene", "builtin_scenes", "export_mitsuba", "git_revision", "gpu_available", "load_scene",
           "render"]
Scene.__module__ = __name__  # shown as pathbench.Scene, where users find it
