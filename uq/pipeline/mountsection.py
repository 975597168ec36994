"""The ``lidar.mount`` section: a tilted (nacelle) lidar's validation.

``lidar.mount: {tilt: 90}`` [deg] tilts the boresight from the deck's vertical towards the
bow; absent or 0 is today's upward lidar, bit for bit. For tilt > 0 ``lidar.azimuths``
are clock positions about the boresight (0 up, 90 starboard, 180 down, 270 port) and
``lidar.ranges`` preview distances along it (:mod:`uq.physics.beams`,
:mod:`uq.physics.nacelle`).
"""
import math

import numpy as np

from uq.physics.beams import beam_unit_vectors
from uq.physics.nacelle import upper_lower

MOUNT_KEYS = ("tilt",)
#: Largest mount tilt [deg]: 90 looks along the bow; beyond it the boresight looks down.
MAX_MOUNT_TILT_DEG = 90.0
#: Smallest singular value of the beams' horizontal parts, relative to the largest, for
#: two beams to determine the horizontal wind (the rank test of the 3-D beams, [1]).
HORIZONTAL_RANK_TOLERANCE = 1e-10


def validate_mount(check, value):
    """``lidar.mount`` as ``{"tilt": deg}``."""
    check.mapping(value, "lidar.mount")
    check.keys(value, "lidar.mount", MOUNT_KEYS)
    if "tilt" not in value:
        check.fail("lidar.mount.tilt", "missing; allowed: a tilt in [0, 90] deg from "
                   "vertical towards the bow (90: a nacelle lidar)")
    return {"tilt": check.number(value["tilt"], "lidar.mount.tilt", low=0.0,
                                 high=MAX_MOUNT_TILT_DEG)}


def tilt_of(lidar):
    """The mount tilt of validated lidar settings [deg] (0 without a mount)."""
    return lidar.get("mount", {}).get("tilt", 0.0)


def check_mounted_beams(check, lidar):
    """The beams of a tilted mount: no vertical beam; 2 beams that see the horizontal wind
    (w = 0 assumed) or >= 3 that determine the 3-D wind."""
    if lidar["vertical_beam"]:
        check.fail("lidar.vertical_beam", "a tilted mount (lidar.mount.tilt > 0) has no "
                   "vertical beam; allowed: false (the beams open about the boresight)")
    vectors = beam_unit_vectors(math.radians(lidar["half_cone"]), np.radians(lidar["azimuths"]),
                                0.0, False, math.radians(tilt_of(lidar)))
    beams = ", ".join(f"{a:g}" for a in lidar["azimuths"])
    if len(lidar["azimuths"]) == 2:
        singular = np.linalg.svd(vectors[:, :2], compute_uv=False)
        if singular[-1] < HORIZONTAL_RANK_TOLERANCE * singular[0]:
            check.fail("lidar.azimuths", f"two beams of a tilted mount ({beams}) must see "
                       "both horizontal components; allowed: e.g. clock positions 90 and 270")
        return
    if len(lidar["azimuths"]) < 2:
        check.fail("lidar.azimuths", "a tilted mount needs 2 beams (w = 0 assumed) or more; "
                   "allowed: e.g. [90, 270] or [0, 90, 180, 270]")
    singular = np.linalg.svd(vectors, compute_uv=False)
    if singular[-1] < HORIZONTAL_RANK_TOLERANCE * singular[0]:
        check.fail("lidar.azimuths", f"the beams ({beams}) do not determine the 3-D wind; "
                   "allowed: 3 or more clock positions not on one line, or 2 (90, 270)")


def check_mount_settings(check, settings):
    """Keys that depend on the mount: the nacelle outputs, tilt2d on two beams."""
    lidar = settings["lidar"]
    tilted = tilt_of(lidar) != 0
    if "shear_exponent" in settings["outputs"] and (
            not tilted or upper_lower(np.radians(lidar["azimuths"])) is None):
        check.fail("outputs", "shear_exponent needs a tilted mount with beams above and "
                   "below the boresight; allowed: lidar.mount.tilt > 0 with clock positions "
                   "0 and 180 (e.g. [0, 90, 180, 270])")
    if tilted and len(lidar["azimuths"]) == 2 and settings["correction"] == "tilt2d":
        check.fail("correction", "tilt2d corrects a 3-D DBS wind, which 2 beams do not "
                   "give; allowed: none, yaw, full, pointwise")
