"""Validation of ``lidar.mount`` and of what depends on it (:mod:`uq.pipeline.mountsection`):
one line naming the file, the key and what is allowed."""
import pytest

import uq
from uq.errors import ScenarioError

BAD = [
    ({"lidar": {"mount": {"tilt": 95}}}, "lidar.mount.tilt"),
    ({"lidar": {"mount": {"tilt": -1}}}, "lidar.mount.tilt"),
    ({"lidar": {"mount": {"tilt": 90, "roll": 1}}}, "lidar.mount"),
    ({"lidar": {"mount": {}}}, "lidar.mount.tilt"),
    ({"lidar": {"mount": {"tilt": 90}, "vertical_beam": True}}, "lidar.vertical_beam"),
    ({"lidar": {"mount": {"tilt": 90}, "azimuths": [0, 180]}}, "lidar.azimuths"),
    ({"lidar": {"mount": {"tilt": 90}, "azimuths": [0, 180, 360.5]}}, "lidar.azimuths"),
    ({"lidar": {"mount": {"tilt": 90}, "azimuths": [90, 270]}, "correction": "tilt2d"},
     "correction"),
    ({"outputs": ["shear_exponent"]}, "outputs"),
    ({"lidar": {"mount": {"tilt": 90}, "azimuths": [90, 270]}, "outputs": ["shear_exponent"]},
     "outputs"),
    ({"motion": {"pitch": []}}, "motion.pitch"),
    ({"motion": {"pitch": [{"amplitude": 1.0}]}}, "motion.pitch[0]"),
]


@pytest.mark.parametrize("changes, key", BAD)
def test_bad_mounts_are_refused_naming_the_key(changes, key):
    """One line naming the file and the key, with what is allowed."""
    with pytest.raises(ScenarioError) as error:
        uq.load_scenario({"name": "bad", **changes})
    message = str(error.value)
    assert key in message and "\n" not in message
    # (the harmonic's own message, older, says what it needs instead of "allowed")
    assert "allowed" in message or "needs" in message



def test_a_tilted_mount_is_in_the_settings_only_when_given():
    """Absent, the settings (and so the scenario text of the results) are today's."""
    assert "mount" not in uq.load_scenario({}).settings["lidar"]
    assert uq.load_scenario({"lidar": {"mount": {"tilt": 90}}}).settings["lidar"]["mount"] \
        == {"tilt": 90.0}
