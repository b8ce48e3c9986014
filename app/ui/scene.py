"""3D view for training demos: a rotor and a load disc per controller, turning with θ_r.

The nodes are client-scoped (``client.scene``) and only updated during a replay, so an idle
page costs nothing. The FDSMC drive stands in front (blue), the conventional one behind (orange).
"""

from __future__ import annotations

import math

import viser

_SHAFT_AXIS_WXYZ = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)  # cylinder Z → Y


def _about_y(angle: float) -> tuple[float, float, float, float]:
    """Quaternion (w, x, y, z) of a rotation by ``angle`` [rad] about the shaft (world Y) axis."""
    return (math.cos(angle / 2.0), 0.0, math.sin(angle / 2.0), 0.0)


class RotorScene:
    """Two drives (rotor, shaft, load disc with a mark); :meth:`show` turns them to θ_r [rad]."""

    def __init__(self, scene: viser.SceneApi) -> None:
        self._frames: dict[str, viser.FrameHandle] = {}
        scene.set_up_direction("+z")
        for key, x, colour in (("fdsmc", -0.45, (31, 111, 209)), ("conventional", 0.45, (232, 89, 12))):
            base = f"/drives/{key}"
            scene.add_box(f"{base}_stator", dimensions=(0.3, 0.3, 0.3), color=(90, 90, 90),
                          position=(x, -0.35, 0.0))
            frame = scene.add_frame(f"{base}/shaft", show_axes=False, position=(x, 0.0, 0.0))
            scene.add_cylinder(f"{base}/shaft/rotor", radius=0.1, height=0.5, color=colour,
                               wxyz=_SHAFT_AXIS_WXYZ, position=(0.0, -0.25, 0.0))
            scene.add_cylinder(f"{base}/shaft/disc", radius=0.3, height=0.06, color=(200, 200, 200),
                               wxyz=_SHAFT_AXIS_WXYZ, position=(0.0, 0.3, 0.0))
            scene.add_box(f"{base}/shaft/mark", dimensions=(0.06, 0.08, 0.26), color=colour,
                          position=(0.0, 0.34, 0.16))
            self._frames[key] = frame

    def show(self, angles: dict[str, float]) -> None:
        """Turn each drive's shaft to its rotor angle θ_r [rad]."""
        for key, angle in angles.items():
            frame = self._frames.get(key)
            if frame is not None:
                frame.wxyz = _about_y(angle)
