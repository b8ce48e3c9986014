"""3D view for training demos: a rotor and a load disc per controller, turning with θ_r.

The nodes are client-scoped (``client.scene``) and only updated during a replay, so an idle
page costs nothing. The FDSMC drive stands left (blue), the conventional one right (orange),
each labelled; the camera looks along the shafts at the load discs and their marks. The view is
folded away by default (:attr:`RotorScene.visible`): on a projector the phase plane and the
time plot carry the result, and the rotors only illustrate it.
"""

from __future__ import annotations

import math

import viser

_SHAFT_AXIS_WXYZ = (math.cos(math.pi / 4), math.sin(math.pi / 4), 0.0, 0.0)  # cylinder Z → Y
#: Camera looking along the shafts (−Y) at the two load discs [m].
CAMERA_POSITION, CAMERA_LOOK_AT = (0.0, 3.2, 0.9), (0.0, 0.0, 0.05)


def _about_y(angle: float) -> tuple[float, float, float, float]:
    """Quaternion (w, x, y, z) of a rotation by ``angle`` [rad] about the shaft (world Y) axis."""
    return (math.cos(angle / 2.0), 0.0, math.sin(angle / 2.0), 0.0)


class RotorScene:
    """Two drives (rotor, shaft, load disc with a mark, label); :meth:`show` turns them to θ_r [rad]."""

    def __init__(self, scene: viser.SceneApi, visible: bool = False) -> None:
        self._frames: dict[str, viser.FrameHandle] = {}
        scene.set_up_direction("+z")
        self._root = scene.add_frame("/drives", show_axes=False, visible=visible)
        # the camera looks along −Y, so +X is on the left of the picture
        for key, label, x, colour in (("fdsmc", "FDSMC", 0.45, (31, 111, 209)),
                                      ("conventional", "Conventional", -0.45, (232, 89, 12))):
            base = f"/drives/{key}"
            scene.add_box(f"{base}_stator", dimensions=(0.3, 0.3, 0.3), color=(90, 90, 90),
                          position=(x, -0.35, 0.0))
            scene.add_label(f"{base}_label", label, position=(x, 0.3, 0.42), font_screen_scale=1.3,
                            anchor="bottom-center")
            frame = scene.add_frame(f"{base}/shaft", show_axes=False, position=(x, 0.0, 0.0))
            scene.add_cylinder(f"{base}/shaft/rotor", radius=0.1, height=0.5, color=colour,
                               wxyz=_SHAFT_AXIS_WXYZ, position=(0.0, -0.25, 0.0))
            scene.add_cylinder(f"{base}/shaft/disc", radius=0.3, height=0.06, color=(200, 200, 200),
                               wxyz=_SHAFT_AXIS_WXYZ, position=(0.0, 0.3, 0.0))
            scene.add_box(f"{base}/shaft/mark", dimensions=(0.06, 0.08, 0.26), color=colour,
                          position=(0.0, 0.34, 0.16))
            self._frames[key] = frame

    @property
    def visible(self) -> bool:
        """Whether the rotors are drawn."""
        return bool(self._root.visible)

    @visible.setter
    def visible(self, value: bool) -> None:
        self._root.visible = bool(value)

    def show(self, angles: dict[str, float]) -> None:
        """Turn each drive's shaft to its rotor angle θ_r [rad]."""
        for key, angle in angles.items():
            frame = self._frames.get(key)
            if frame is not None:
                frame.wxyz = _about_y(angle)


def aim_camera(camera: viser.CameraHandle) -> None:
    """Point a client's camera along the shafts at both load discs."""
    camera.up_direction = (0.0, 0.0, 1.0)
    camera.position = CAMERA_POSITION
    camera.look_at = CAMERA_LOOK_AT
