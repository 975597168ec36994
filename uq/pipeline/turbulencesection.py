"""Scenario keys of a turbulent atmosphere and of ten-minute records: the ``turbulence``
and ``record`` sections; and the :class:`uq.physics.scangeometry.ScanGeometry` of a
scenario, which both turbulence paths read.

Absent, the scenario is today's, bit for bit (neither section enters the validated
settings unless given).

.. code-block:: yaml

    turbulence:                  # a frozen turbulent field on top of the mean flow of `wind`
      model: mann                # mann | kaimal
      intensity: 0.1             # sigma_u / U of the point field at wind.reference_height
      length_scale: 33.6         # m: Mann's L (default 0.8 Lambda_1), Kaimal's L_u
                                 # (default 8.1 Lambda_1); IEC 61400-1 Ed. 3, Annex B
      anisotropy: 3.9            # Mann's Gamma (default 3.9, IEC 61400-1 Ed. 3, Annex B)
    record: {duration: 600, count: 20}   # s: a record is the scans lidar.scan times in
                                 # that long; count: Monte Carlo records per scene

Defaults (:mod:`uq.constants`, block "Turbulence defaults"): the length scale
follows IEC 61400-1 Ed. 3 from the reference height z through the turbulence scale
parameter ``Lambda_1 = 0.7 min(z, 60 m)`` (42 m above 60 m); ``anisotropy`` 3.9.
``intensity`` has no default: it is what a site is measured for (offshore 4-8 %, the IEC
classes' 12-16 % at 15 m s-1 are design values, not a site's), and a default would give a
plausible-looking apparent TI of a turbulence nobody stated.

Geometry (:func:`scan_geometry`): the scan of the scenario's configured beams at the
static attitude of ``ship`` (heading, pitch, roll), without motion, in the mean-wind
frame of :mod:`uq.physics.scangeometry` (x downwind, y left, z up; origin the reference
point, on the lidar's vertical at ``wind.reference_height``).
"""
import math

import numpy as np

from uq.constants import (KAIMAL_LENGTH_FACTOR, MANN_ANISOTROPY, MANN_LENGTH_FACTOR,
                          MAX_ANISOTROPY, RECORD_MAX_BOX_CELLS, MAX_KAIMAL_POINTS, MAX_LENGTH_SCALE,
                          CW_RECORD_FAR_CUT, CW_RECORD_PROBE_NODES,
                          MAX_RECORD_DURATION, MAX_RECORD_SCANS, MAX_RECORDS,
                          MAX_TURBULENCE_INTENSITY, MIN_TURBULENCE_INTENSITY,
                          MOTION_REACH_SIGMAS, DEFAULT_RECORDS, TURBULENCE_PROBE_NODES)
from uq.physics import nacelle
from uq.physics.beams import beam_unit_vectors, least_squares_operator, slant_distances
from uq.physics.probe import legendre
from uq.physics.rotation import attitude_matrix, rotate_vectors
from uq.physics.scangeometry import ScanGeometry, earth_to_wind_frame
from uq.physics.spectraltensor import iec_scale_parameter
from uq.pipeline import probesection
from uq.pipeline.motionsection import SCAN_DEFAULTS
from uq.pipeline.mountsection import tilt_of

#: Turbulence models (``turbulence.model``).
TURBULENCE_MODELS = ("mann", "kaimal")
TURBULENCE_KEYS = ("model", "intensity", "length_scale", "anisotropy")
RECORD_KEYS = ("duration", "count")
#: IEC 61400-1's length scale of each model per Lambda_1 [1] (:mod:`uq.constants`).
LENGTH_FACTORS = {"mann": MANN_LENGTH_FACTOR, "kaimal": KAIMAL_LENGTH_FACTOR}


def default_length_scale(model, height):
    """The IEC 61400-1 length scale [m] of `model` at `height` [m]: Mann's L = 0.8
    Lambda_1, Kaimal's L_u = 8.1 Lambda_1.

    >>> round(default_length_scale("mann", 100.0), 12), round(default_length_scale("kaimal", 100.0), 12)
    (33.6, 340.2)
    """
    return LENGTH_FACTORS[model] * float(iec_scale_parameter(height))   # Lambda_1, Eq. 5


def validate_turbulence(check, value, reference_height):
    """The validated ``turbulence`` section, defaults filled in (m, 1)."""
    check.mapping(value, "turbulence")
    check.keys(value, "turbulence", TURBULENCE_KEYS)
    check.required(value, "turbulence", ("intensity",), "allowed: sigma_u / U of the "
                   "field at wind.reference_height, e.g. 0.06 (no default: it is the site's)")
    model = check.choice(value.get("model", "mann"), "turbulence.model", TURBULENCE_MODELS)
    length = value.get("length_scale", default_length_scale(model, reference_height))
    return {"model": model,
            "intensity": check.number(value["intensity"], "turbulence.intensity",
                                      low=MIN_TURBULENCE_INTENSITY,
                                      high=MAX_TURBULENCE_INTENSITY),
            "length_scale": check.number(length, "turbulence.length_scale", low=0.0,
                                         high=MAX_LENGTH_SCALE, low_open=True),
            "anisotropy": check.number(value.get("anisotropy", MANN_ANISOTROPY),
                                       "turbulence.anisotropy", low=0.0, high=MAX_ANISOTROPY)}


def validate_record(check, value, n_beams, lidar):
    """The validated ``record`` section [s]; refuses a record shorter than one scan or of
    more than :data:`~uq.constants.MAX_RECORD_SCANS` scans (counted, not allocated)."""
    check.mapping(value, "record")
    check.keys(value, "record", RECORD_KEYS)
    duration = check.number(value.get("duration", 600.0), "record.duration", low=0.0,
                            high=MAX_RECORD_DURATION, low_open=True)
    period = n_beams * beam_duration(lidar)
    scans = math.floor(duration / period + 1e-9)          # (rounding of e.g. 600 / 0.005)
    if scans < 1:
        check.fail("record.duration", f"{duration:g} s is shorter than one scan ({n_beams} "
                   f"beams of {beam_duration(lidar):g} s); allowed: at least {period:g} s")
    if scans > MAX_RECORD_SCANS:
        check.fail("record.duration", f"{duration:g} s holds {scans} scans of {period:g} s; "
                   f"allowed: at most {MAX_RECORD_SCANS} scans (a shorter record or longer "
                   "lidar.scan.beam_duration)")
    count = check.integer(value.get("count", DEFAULT_RECORDS), "record.count", low=2,
                          high=MAX_RECORDS)
    return {"duration": duration, "count": count}


def check_record_cost(check, settings):
    """Refuse, before anything is made, a record mode the model cannot take: no mean wind
    to carry the frozen field (``wind.speed`` 0), or Monte Carlo records whose turbulence
    box (:func:`uq.physics.turbulencebox.box_extent`: the record's advected length by the
    scan's width and height with its margins, at the spacing of the length scale, and
    the largest displacement the platform's motion can give a probe point,
    :func:`motion_reach`) is above :data:`~uq.constants.RECORD_MAX_BOX_CELLS` cells, or, for
    Kaimal, above :data:`~uq.constants.MAX_KAIMAL_POINTS` points across the wind. One
    line naming the key to change and how far: the longest ``record.duration`` at this
    wind speed, else the smallest ``turbulence.length_scale`` for this lidar. Counted,
    not allocated; ``sampling.method: none`` makes no box."""
    from uq.physics import turbulencebox
    if not settings["wind"]["speed"] > 0:
        check.fail("wind.speed", f"{settings['wind']['speed']:g} m/s with a turbulence "
                   "section: a frozen turbulent field needs a mean wind to carry it past "
                   "the lidar (Taylor); allowed: wind.speed > 0")
    if settings["sampling"]["method"] == "none":
        return
    geometry = scan_geometry(settings)
    turbulence = settings["turbulence"]
    model = turbulence["model"]
    margin = motion_reach(settings, geometry)

    def box(length, duration):
        scale = length if model == "mann" else length / KAIMAL_LENGTH_FACTOR
        return turbulencebox.box_extent(geometry, scale, model, record_duration=duration,
                                        motion_margin=margin)[0]

    def across(length, duration):        # the (y, z) nodes a Kaimal record makes
        grid = turbulencebox.box_for(geometry, length / KAIMAL_LENGTH_FACTOR, model,
                                     record_duration=duration, motion_margin=margin,
                                     max_cells=RECORD_MAX_BOX_CELLS)
        return int(turbulencebox.kaimal_nodes(grid, record_points(geometry), margin).sum())

    def fits(length, duration):
        shape = box(length, duration)
        if math.prod(int(n) for n in shape) > RECORD_MAX_BOX_CELLS:
            return False
        return model == "mann" or across(length, duration) <= MAX_KAIMAL_POINTS
    length, duration = turbulence["length_scale"], settings["record"]["duration"]
    if fits(length, duration):
        return
    shape = box(length, duration)
    cells = math.prod(int(n) for n in shape)
    size = (f"a turbulence box of {' x '.join(f'{n:.0f}' for n in shape)} = "
            f"{float(cells):.3g} cells" + (
                f" ({across(length, duration)} points across the wind)"
                if model == "kaimal" and cells <= RECORD_MAX_BOX_CELLS else ""))
    limit = (f"at most {RECORD_MAX_BOX_CELLS} cells" + (
        f" and {MAX_KAIMAL_POINTS} points across the wind" if model == "kaimal" else ""))
    period = geometry.scan_period
    larger = (f"turbulence.length_scale >= "
              f"{_bisect(lambda L: fits(L, duration), MAX_LENGTH_SCALE, length, log=True):.3g} "
              "m (a cell is L / 8)" if fits(MAX_LENGTH_SCALE, duration) else None)
    if fits(length, period):
        longest = _bisect(lambda d: fits(length, d), period, duration)
        check.fail("record.duration", f"{duration:g} s at wind.speed "
                   f"{settings['wind']['speed']:g} m/s needs {size}; allowed: {limit}, i.e. "
                   f"record.duration <= {longest:.4g} s at this wind speed (or a lower "
                   "wind.speed" + (f", or {larger}" if larger else "") + ", or "
                   "sampling.method: none for the spectral path alone)")
    check.fail("turbulence.length_scale", f"{length:g} m needs {size} (a cell is L / 8); "
               f"allowed: {limit}, i.e. {larger or 'a shorter record.duration'} for this "
               "lidar (or sampling.method: none for the spectral path alone)")


def record_points(geometry):
    """The points a record's box must hold, (n, 3) [m]: every probe point of the scan
    and the reference point (0, 0, 0)."""
    return np.vstack([np.asarray(geometry.probe_points()).reshape(-1, 3), np.zeros(3)])


def _bisect(inside, good, bad, log=False, steps=60):
    """The boundary [unit of good] between `good` (inside) and `bad` (not) by bisection
    (geometric where `log`): the last value found inside."""
    if inside(bad):
        return bad
    for _ in range(steps):
        middle = math.sqrt(good * bad) if log else (good + bad) / 2
        good, bad = (middle, bad) if inside(middle) else (good, middle)
    return good


def motion_reach(settings, geometry):
    """How far the platform's motion moves a probe point within a record [m], a bound
    (:func:`uq.pipeline.beammotion.motion_margin` is the record's own): per axis of
    translation (surge, sway, heave) and for the rotation angle theta (all rotational
    amplitudes) the smaller of the amplitudes' sum (the most the harmonics can add to)
    and :data:`~uq.constants.MOTION_REACH_SIGMAS` standard deviations ``sqrt(sum A^2 /
    2)`` (the most a sum of many random-phase harmonics reaches in a record); the
    rotation turns the lever arm r and the beams out to their farthest probe point,
    ``|(R - R_static) x| <= |x| min(theta, 2)``; 0 without motion."""
    from uq.pipeline.motionsection import time_resolved
    resolved = time_resolved(settings)
    if resolved is None or not resolved.motion.components:
        return 0.0
    amplitudes = np.abs(np.array([c.amplitudes for c in resolved.motion.components]))

    def reach(a):              # a: (K, n) amplitudes of n axes added, or of one angle
        return min(float(a.sum()), MOTION_REACH_SIGMAS * math.sqrt(float(np.sum(a ** 2)) / 2))
    translation = math.sqrt(sum(reach(amplitudes[:, d]) ** 2 for d in range(3, 6)))
    angle = min(reach(amplitudes[:, :3]), 2.0)
    reach = float(np.max(slant_ranges(settings["lidar"]))) + float(
        np.max(np.abs(geometry.probe_offsets)))
    return translation + (float(np.linalg.norm(resolved.motion.lever_arm)) + reach) * angle


def beam_duration(lidar):
    """``lidar.scan.beam_duration`` [s] of a validated ``lidar`` section (its default)."""
    return {**SCAN_DEFAULTS, **lidar.get("scan", {})}["beam_duration"]


def scans_per_record(settings):
    """Whole scans in one record of validated `settings` (the partial last scan of a
    record is not reported by a lidar's software, nor here)."""
    lidar = settings["lidar"]
    period = (len(lidar["azimuths"]) + int(lidar["vertical_beam"])) * beam_duration(lidar)
    return math.floor(settings["record"]["duration"] / period + 1e-9)


def scan_geometry(settings):
    """The :class:`ScanGeometry` of validated `settings` (degrees, as in the file).

    * directions: the configured beams (:func:`uq.physics.beams.beam_unit_vectors`) at the
      static attitude of ``ship`` (heading, pitch, roll; marine convention), rotated into
      the mean-wind frame (x downwind, y left, z up) of ``wind.direction`` ("from").
    * gate centres: the lidar at ``lidar.height`` on the vertical of the reference point,
      each gate at the configured slant distance (``range / cos(half_cone)``, ``range``
      for the vertical beam) along its beam; z relative to ``wind.reference_height``.
    * times: the middle of each beam's dwell, ``(k + 1/2) D`` for beam k (beams one after
      another in the order of ``lidar.azimuths``, then the vertical beam;
      :mod:`uq.physics.timing`); ``dwell`` D where ``lidar.scan.dwell_average`` is on,
      else 0 (a line of sight at its time stamp); ``scan_period`` ``n_beams D``.
    * probe: one node at 0 for a point probe; else
      :data:`~uq.constants.TURBULENCE_PROBE_NODES` nodes of the probe's own rule
      (:mod:`uq.physics.probe`) at the slanted beams' focus of each gate; where the
      gates' nodes differ (a CW focus), the nodes of every gate side by side, each gate
      weighting only its own. The vertical beam takes its gate's weighting (for a CW
      lidar its Rayleigh length is cos^2(half_cone) times the slanted beams').
    * reconstruction: the operator the lidar's software applies to a scan at rest, the
      same at every gate (:func:`reconstruction_operator`: the least-squares
      pseudo-inverse of the directions; a tilted mount's hub-height wind or its two
      beams' horizontal wind).
    * a tilted mount (``lidar.mount.tilt``, a nacelle lidar): its beams about the tilted
      boresight (clock positions, :mod:`uq.physics.beams`), its ranges preview distances
      along the boresight, each gate ``range / cos(half_cone)`` along its beam.
    * speed: ``wind.speed`` (at the reference height); ``record_duration``:
      ``record.duration``, or inf without a record.
    """
    lidar, ship, wind = settings["lidar"], settings["ship"], settings["wind"]
    directions = _beam_directions(lidar, ship, wind["direction"])
    n_beams = directions.shape[0]
    slant = slant_distances(lidar["ranges"], math.radians(lidar["half_cone"]),
                            len(lidar["azimuths"]), lidar["vertical_beam"])   # (b, g)
    lift = lidar["height"] - wind["reference_height"]
    centres = slant[..., None] * directions[:, None, :] + np.array([0.0, 0.0, lift])
    scan = {**SCAN_DEFAULTS, **lidar.get("scan", {})}
    duration = scan["beam_duration"]
    offsets, weights = probe_quadrature(lidar.get("probe"), slant_ranges(lidar))
    operator = reconstruction_operator(directions, lidar)
    record = settings.get("record")
    return ScanGeometry(
        directions=directions, gate_centres=centres,
        times=(np.arange(n_beams) + 0.5) * duration,
        dwell=duration if scan["dwell_average"] else 0.0, scan_period=n_beams * duration,
        probe_offsets=offsets, probe_weights=weights,
        reconstruction=np.broadcast_to(operator, (len(lidar["ranges"]),) + operator.shape).copy(),
        speed=wind["speed"], record_duration=record["duration"] if record else np.inf)


def slant_ranges(lidar):
    """Each gate's distance from the lens along its slanted beams [m], shape (n_gates,):
    ``range / cos(half_cone)`` (a range is a height above an upward lidar, a preview
    distance along a tilted one's boresight); a CW lidar's focus."""
    return np.asarray(lidar["ranges"], dtype=float) / math.cos(math.radians(lidar["half_cone"]))


def reconstruction_operator(directions, lidar):
    """The linear operator (3, n_beams) from a scan's radial velocities to the wind its
    software reconstructs at rest [1], for beams `directions` (n_beams, 3) in a frame
    with z up (a turn about z commutes with it):

    * an upward lidar, or a tilted mount's beams that determine the 3-D wind without a
      level pair: the least-squares pseudo-inverse ``(D^T D)^-1 D^T``;
    * a tilted mount with two beams: the horizontal least squares with w = 0 assumed
      (:func:`uq.physics.nacelle.horizontal_least_squares`: ``[(D_h^T D_h)^-1 D_h^T;
      0]``);
    * a tilted mount with its level pair (clock positions 90 and 270): w from the full
      least squares, the horizontal wind from the pair less its vertical part
      (:func:`uq.physics.nacelle.hub_height_wind`: ``u_h = D_p,h^-1 (v_p - d_p,z w)``).
    """
    directions = np.asarray(directions, dtype=float)
    full = least_squares_operator(directions)
    if tilt_of(lidar) == 0:
        return full
    if len(lidar["azimuths"]) == 2:                   # w = 0 assumed: two beams
        out = np.zeros_like(full)
        out[:2] = np.linalg.pinv(directions[:, :2])
        return out
    pair = nacelle.level_pair(np.radians(lidar["azimuths"]))
    if pair is None:
        return full
    pair = list(pair)
    select = np.zeros((2, directions.shape[0]))
    select[[0, 1], pair] = 1.0
    vertical = full[2]                                          # w: full least squares
    horizontal = np.linalg.solve(directions[pair, :2],
                                 select - np.outer(directions[pair, 2], vertical))
    return np.vstack([horizontal, vertical])


def _beam_directions(lidar, ship, direction):
    """Unit vectors of the beams at the static attitude, in the mean-wind frame (a tilted
    mount's about its boresight)."""
    ship_frame = beam_unit_vectors(math.radians(lidar["half_cone"]),
                                   np.radians(lidar["azimuths"]),
                                   math.radians(lidar["misalignment"]), lidar["vertical_beam"],
                                   math.radians(tilt_of(lidar)))
    attitude = attitude_matrix(*np.radians([ship["heading"], ship["pitch"], ship["roll"]]))
    return earth_to_wind_frame(rotate_vectors(attitude, ship_frame), direction)


def probe_quadrature(probe_settings, focus, nodes=TURBULENCE_PROBE_NODES):
    """Offsets along the beam [m], shape (n_nodes,), and weights, shape (n_gates,
    n_nodes), of the probe of a validated ``lidar.probe`` at the focus of each gate [m]
    (see :func:`scan_geometry`): each row sums to 1, but a CW lidar's, whose weighting is
    the Lorentzian cut at the lens alone, read up to :data:`~uq.constants.
    CW_RECORD_FAR_CUT` focus distances beyond the focus on a "tan" rule of
    :data:`~uq.constants.CW_RECORD_PROBE_NODES` nodes (s = z_R tan(theta), theta
    uniform between ``-atan(F / z_R)`` and ``atan(c F / z_R)``, weights normalised over
    ``s >= -F``): the tail beyond is dropped (its weight, ~2 z_R / (3 pi F), reads no
    field), not spread over the rest."""
    probe = probesection.make_probe(probe_settings)
    n_gates = np.size(focus)
    if probe is None:
        return np.zeros(1), np.ones((n_gates, 1))
    if probe.kind == "cw":
        nodes = CW_RECORD_PROBE_NODES
        x, w = legendre(nodes)
        rules = []
        for f in np.asarray(focus, float):
            z = float(probe.rayleigh(np.array([f]))[0])
            low, high = -math.atan(f / z), math.atan(CW_RECORD_FAR_CUT * f / z)
            theta = (low + high) / 2 + (high - low) / 2 * x
            mass = 0.5 + math.atan(f / z) / math.pi          # of the weighting on s >= -F
            rules.append((z * np.tan(theta), (high - low) / 2 * w / (math.pi * mass)))
        offsets = [s for s, _ in rules]
        weights = [omega for _, omega in rules]
    else:
        x, w = legendre(nodes)
        # the probe's own rule (uq.physics.probe: nodes on its cut interval with weights
        # w_i W(s_i)), gate by gate
        rules = [probe._node(x, w, f, probe.parameters()) for f in np.asarray(focus, float)]
        offsets = [np.broadcast_to(s, x.shape) for s, _ in rules]
        weights = [np.broadcast_to(omega, x.shape) / np.sum(omega) for _, omega in rules]
    if all(np.array_equal(o, offsets[0]) for o in offsets):
        return np.array(offsets[0]), np.array(weights)
    table = np.zeros((n_gates, n_gates * nodes))
    for gate, row in enumerate(weights):
        table[gate, gate * nodes:(gate + 1) * nodes] = row
    return np.concatenate(offsets), table
