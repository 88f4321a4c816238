"""A glTF 2.0 binary buffer built mesh by mesh, for the scripts that write the
project's glTF scenes (scenes/examples/make_gltf_example.py,
tests/data/scenes/formats/make_format_scenes.py)."""
from __future__ import annotations

import base64
import struct


class Buffer:
    def __init__(self):
        self.blob, self.views, self.accessors = b"", [], []

    def _add(self, data: bytes, target: int, accessor: dict) -> int:
        self.blob += b"\0" * (-len(self.blob) % 4)  # 4-byte aligned views
        self.views.append({"buffer": 0, "byteOffset": len(self.blob), "byteLength": len(data), "target": target})
        self.blob += data
        self.accessors.append(dict(accessor, bufferView=len(self.views) - 1))
        return len(self.accessors) - 1

    def mesh(self, points, faces, material: int, name: str | None = None) -> dict:
        """A glTF mesh of one indexed triangle primitive (float positions, ushort indices)."""
        flat = [c for p in points for c in p]
        pos = self._add(struct.pack("<%df" % len(flat), *flat), 34962,
                        {"componentType": 5126, "count": len(points), "type": "VEC3",
                         "min": [min(p[i] for p in points) for i in range(3)],
                         "max": [max(p[i] for p in points) for i in range(3)]})
        idx = [i for f in faces for i in f]
        ind = self._add(struct.pack("<%dH" % len(idx), *idx), 34963,
                        {"componentType": 5123, "count": len(idx), "type": "SCALAR"})
        m = {"primitives": [{"attributes": {"POSITION": pos}, "indices": ind, "material": material}]}
        return dict(m, name=name) if name else m

    def finish(self, gltf: dict) -> dict:
        """`gltf` with the views, accessors and the buffer embedded as base64."""
        return dict(gltf, bufferViews=self.views, accessors=self.accessors,
                    buffers=[{"byteLength": len(self.blob),
                              "uri": "data:application/octet-stream;base64," + base64.b64encode(self.blob).decode()}])
