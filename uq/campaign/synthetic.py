"""The shipped synthetic campaign ``campaign_buoy``: a real mast's records as the truth, a
buoy in a sea whose state changes from record to record, and the buoy's lidar records
made by uq's own Monte Carlo records.

* **Truth**: a stretch of the brightwind demo mast (:func:`uq.data.brightwind_mast`, MIT
  licence): each record's mean speed, its standard deviation and direction at 40, 60 and
  80 m. The field of the record is a Mann field (:data:`TURBULENCE`) of mean speed U the
  mast's and of u-variance at the gate ``V`` with ``sqrt(V N / (N - 1)) / U`` (a point
  sampled once a scan, the record's high-pass, the variance over N - 1 scans as the
  lidar's) the mast's TI. The mast's table then holds what an ideal cup anemometer at
  the gate reads of that field on average (:func:`cup_reading`): like every sensor that
  averages the horizontal speed, the lidar included, its mean is the mean vector's
  length plus the lateral turbulence's second-order share ``sigma_v^2 / (2 U)`` (0.2-2 %
  of U on 90 % of the records, 8 % at TI 0.4). Its TI is the record's true TI (``turbulence_intensity_
  reference``), on the convention of a mast's and a lidar's ten-minute statistics.
* **Sea**: the significant wave height follows the wind at 80 m (a swell and the fully
  developed wind sea) with a slowly wandering factor (an AR(1) process of the records,
  :data:`SEA`), the peak period the wave height (``Tp ~ 3.3 sqrt(Hs) + 2`` with noise);
  both written as a wave sensor's table (UTC, stamps at the period's start).
* **Lidar**: each record and height is one Monte Carlo record
  (:func:`uq.campaign.adapter.monte_carlo_record`) of the lidar's scenario
  (``campaign_buoy_lidar.yaml``: it does not correct its motion) at the gate, in the
  record's wind (speed, direction, the scenario's shear), field and sea (JONSWAP,
  the buoy's response): the turbulence box, the motion, the probe and the radial noise.
  Its mean speed and standard deviation (``ddof`` 1) of the scans are the record's. The
  lidar's table is written as a logger writes it: its own column names, local time
  (UTC+01:00) stamped at the period's end, an availability per height; some records
  lost (rows absent), some with a low availability, and those uq's Monte Carlo records
  may not make left empty (:data:`NOT_MADE`).

Each record and height has its own random stream (:func:`record_stream`), so one record
can be made again alone (the tests do, against the shipped table).
"""
import dataclasses
from pathlib import Path

import numpy as np
import pandas as pd

from uq.campaign import adapter
from uq.constants import CAMPAIGN_RECORD_SECONDS

HEIGHTS = (40.0, 60.0, 80.0)
#: brightwind demo mast: height [m] -> (speed, its standard deviation, vane) columns.
MAST_COLUMNS = {40.0: ("Spd40mN", "Spd40mNStd", "Dir38mS"),
                60.0: ("Spd60mN", "Spd60mNStd", "Dir58mS"),
                80.0: ("Spd80mN", "Spd80mNStd", "Dir78mS")}
#: The field of every record: Mann, one length scale at every height (the campaign's
#: configuration states it), IEC 61400-1's Gamma.
TURBULENCE = {"model": "mann", "length_scale": 33.6, "anisotropy": 3.9}
#: The sea: Hs = (base + coefficient U80^2) x factor, the factor's log an AR(1) of the
#: records (correlation per record, standard deviation), clipped to [low, high] [m]: a
#: swell of 0.5 m and the fully developed wind sea of Pierson and Moskowitz (1964), Hs
#: = 0.21 U^2 / g = 0.0214 U^2; Tp = a sqrt(Hs) + b + noise [s], clipped to [low, high].
SEA = {"base": 0.5, "coefficient": 0.0214, "correlation": 0.98, "spread": 0.3,
       "hs_range": (0.2, 4.0), "tp_a": 3.3, "tp_b": 2.0, "tp_noise": 0.4,
       "tp_range": (3.0, 14.0)}
#: JONSWAP of the records (the lidar scenario's response moves the buoy).
SPECTRUM = {"gamma": 3.3, "components": 24}
#: Records made: mast speeds at least this [m s-1] (the lidar reads the others too, but
#: the Monte Carlo records need a mean flow) and TI at most this [1] (uq's turbulence
#: limit is 0.5).
MADE = {"min_speed": 1.0, "max_ti": 0.45}
#: Losses: the share of records whose rows are absent, the share with a low
#: availability and its range [%].
LOSSES = {"absent": 0.03, "low": 0.03, "low_range": (40.0, 79.0)}
#: The lidar logger's local time zone and stamp.
LOCAL_ZONE, LOCAL_OFFSET = "+01:00", pd.Timedelta(hours=1)
#: What :func:`make_records` keeps for a record uq's Monte Carlo records may not make:
#: a turbulence box larger than uq allows (:data:`uq.constants.MAX_BOX_CELLS`: a fast
#: wind over a high sea, whose motion widens the box) or a field more turbulent than its
#: limit (:data:`uq.constants.MAX_TURBULENCE_INTENSITY`: a gusty record at a low speed,
#: whose ten-minute high-pass leaves a small share of the field's variance). Not made,
#: its row is left empty in the lidar's table (a record the logger lost).
NOT_MADE = -1.0
#: The lidar's standard deviation is over N - DDOF scans; the record's true TI is on the
#: same convention (its expected variance over N - 1 scans: the square of the mast's TI).
DDOF = 1
#: Spawn keys of the random streams: the sea, the losses, the records.
SEA_STREAM, LOSS_STREAM, RECORD_STREAM = 1, 2, 3


@dataclasses.dataclass(frozen=True)
class Stretch:
    """The shipped stretch: the mast's records from `start` (included) to `stop`
    (excluded), UTC, and the seed of every random stream."""

    start: str = "2016-03-02"
    stop: str = "2016-03-03"
    seed: int = 2016


def truth(stretch):
    """The mast's records of the stretch (pandas, indexed by the UTC period start)."""
    from uq.data import brightwind_mast
    mast = brightwind_mast()
    mast.index = pd.DatetimeIndex(mast.index, name="time")
    keep = (mast.index >= pd.Timestamp(stretch.start)) & (mast.index < pd.Timestamp(stretch.stop))
    return mast.loc[keep]


def sea_states(speed80, seed):
    """(Hs [m], Tp [s]) of each record (module docstring, :data:`SEA`); record i's random
    numbers are its own stream's (a longer stretch keeps the first records' sea)."""
    n = len(speed80)
    draws = np.array([_stream(seed, SEA_STREAM, i).standard_normal(2) for i in range(n)])
    draws = draws.reshape(n, 2)
    log_factor = np.zeros(n)
    for i in range(n):
        shock = SEA["spread"] * draws[i, 0]
        log_factor[i] = shock if i == 0 else SEA["correlation"] * log_factor[i - 1] + \
            np.sqrt(1 - SEA["correlation"] ** 2) * shock
    speed = np.nan_to_num(np.asarray(speed80, float), nan=0.0)
    hs = np.clip((SEA["base"] + SEA["coefficient"] * speed ** 2) * np.exp(log_factor),
                 *SEA["hs_range"])
    tp = np.clip(SEA["tp_a"] * np.sqrt(hs) + SEA["tp_b"] + SEA["tp_noise"] * draws[:, 1],
                 *SEA["tp_range"])
    return hs, tp


def _stream(seed, kind, record):
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(kind, record)))


def record_stream(seed, record, height_index):
    """The random generator of one record at one height."""
    return np.random.default_rng(np.random.SeedSequence(seed, spawn_key=(
        RECORD_STREAM, record, height_index)))


def record_settings(lidar, height, speed, direction, truth_ti, hs, tp):
    """Validated gate settings of one record: the record's wind, the field whose expected
    ten-minute TI at the gate is `truth_ti`, and its sea."""
    scan = adapter.scan_period(lidar)
    n = int(np.floor(CAMPAIGN_RECORD_SECONDS / scan + 1e-9))
    point = adapter.point_record_variance(TURBULENCE["length_scale"],
                                          TURBULENCE["anisotropy"], 1.0, speed, scan,
                                          CAMPAIGN_RECORD_SECONDS) / speed ** 2
    point *= n / (n - DDOF)                  # the lidar's convention: over N - 1 scans
    motion = {"spectrum": {"kind": "jonswap", "hs": float(hs), "tp": float(tp),
                           **SPECTRUM},
              "response": lidar["motion"]["response"]}
    return adapter.gate_settings(lidar, [height], TURBULENCE, CAMPAIGN_RECORD_SECONDS,
                                 speed, direction, intensity=truth_ti / np.sqrt(point),
                                 motion=motion)


def lidar_record(lidar, height, speed, direction, truth_ti, hs, tp, rng):
    """(mean speed, its standard deviation (ddof 1)) [m s-1] of one Monte Carlo record."""
    settings = record_settings(lidar, height, speed, direction, truth_ti, hs, tp)
    vh, _ = adapter.monte_carlo_record(settings, rng)
    return float(np.mean(vh)), float(np.std(vh, ddof=DDOF))


def plan(stretch):
    """The stretch's truth and sea: a table with, per record, the mast's speed, std,
    direction and TI per height, Hs and Tp, whether it is made, lost or low."""
    mast = truth(stretch)
    table = pd.DataFrame(index=mast.index)
    for h, (speed, std, vane) in MAST_COLUMNS.items():
        table[f"speed_{h:g}"] = mast[speed]
        table[f"std_{h:g}"] = mast[std]
        table[f"direction_{h:g}"] = mast[vane]
        with np.errstate(divide="ignore", invalid="ignore"):
            table[f"ti_{h:g}"] = mast[std] / mast[speed]
    table["hs"], table["tp"] = sea_states(table["speed_80"].to_numpy(), stretch.seed)
    draws = np.array([_stream(stretch.seed, LOSS_STREAM, i).random(3)
                      for i in range(len(table))]).reshape(len(table), 3)
    table["absent"] = draws[:, 0] < LOSSES["absent"]
    low, span = draws[:, 1] < LOSSES["low"], LOSSES["low_range"]
    table["availability"] = np.where(low, span[0] + (span[1] - span[0]) * draws[:, 2], 100.0)
    for h in HEIGHTS:
        made = (table[f"speed_{h:g}"] >= MADE["min_speed"]) & (
            table[f"ti_{h:g}"] <= MADE["max_ti"]) & ~table["absent"]
        table[f"made_{h:g}"] = made.fillna(False)
    return table


def make_records(lidar, table, stretch, done=None, report=None, part=(0, 1)):
    """Mean and std of every made record and height: a table (index of `table`) with
    columns ``mean_H``, ``std_H``; `done` (such a table) records already made (kept);
    `report(index, total)` is called after each record; `part` (i, n): only the records
    whose index is i modulo n (n processes share the work)."""
    out = done.copy() if done is not None else pd.DataFrame(index=table.index)
    for h in HEIGHTS:
        for name in (f"mean_{h:g}", f"std_{h:g}"):
            if name not in out:
                out[name] = np.nan
    jobs = [(i, j, h) for i in range(part[0], len(table), part[1])
            for j, h in enumerate(HEIGHTS)
            if table[f"made_{h:g}"].iloc[i] and not np.isfinite(out[f"mean_{h:g}"].iloc[i])]
    for count, (i, j, h) in enumerate(jobs):
        row = table.iloc[i]
        try:
            mean, std = lidar_record(lidar, h, row[f"speed_{h:g}"], row[f"direction_{h:g}"],
                                     row[f"ti_{h:g}"], row["hs"], row["tp"],
                                     record_stream(stretch.seed, i, j))
        except ValueError as error:       # ScenarioError is one: the field's intensity
            if "turbulence box" not in str(error) and "turbulence.intensity" not in str(error):
                raise
            mean, std = NOT_MADE, NOT_MADE           # beyond what uq may make: lost
        out.iloc[i, out.columns.get_loc(f"mean_{h:g}")] = mean
        out.iloc[i, out.columns.get_loc(f"std_{h:g}")] = std
        if report is not None:
            report(count + 1, len(jobs), out)
    return out


LIDAR_COLUMNS = {"speed": "Horizontal Wind Speed (m/s) at {h}m",
                 "std": "Horizontal Wind Speed Std. Dev. (m/s) at {h}m",
                 "direction": "Wind Direction (deg) at {h}m",
                 "availability": "Data Availability (%) at {h}m"}
LIDAR_TIME = "Date and Time (UTC+01:00, end of period)"


def write_files(table, records, folder, lidar):
    """The three tables a user would hold (module docstring) in `folder`; `lidar` the
    lidar's validated settings (its scan period: the mast's cup is read once a scan)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    lidar = pd.DataFrame(index=table.index)
    for h in HEIGHTS:
        name = f"{h:g}"
        made = table[f"made_{name}"].to_numpy() & (records[f"mean_{name}"].to_numpy()
                                                  != NOT_MADE)
        lidar[LIDAR_COLUMNS["speed"].format(h=name)] = np.where(made, records[f"mean_{name}"], np.nan)
        lidar[LIDAR_COLUMNS["std"].format(h=name)] = np.where(made, records[f"std_{name}"], np.nan)
        lidar[LIDAR_COLUMNS["direction"].format(h=name)] = np.where(
            made, table[f"direction_{name}"], np.nan)
        lidar[LIDAR_COLUMNS["availability"].format(h=name)] = np.where(
            made, table["availability"], 0.0)
    lidar = lidar[~table["absent"].to_numpy()]
    stamps = (lidar.index + pd.Timedelta(minutes=10) + LOCAL_OFFSET).strftime("%Y-%m-%d %H:%M")
    lidar.insert(0, LIDAR_TIME, stamps)
    lidar.to_csv(folder / "lidar.csv", index=False, float_format="%.4f")
    waves = pd.DataFrame({"time_utc": table.index.strftime("%Y-%m-%dT%H:%M:%SZ"),
                          "Hm0 [m]": table["hs"].round(3), "Tp [s]": table["tp"].round(2)})
    waves.to_csv(folder / "waves.csv", index=False)
    write_mast(table, folder, adapter.scan_period(lidar))


def write_mast(table, folder, scan_period):
    """The mast's table in `folder`: each record's ideal cup reading (:func:`cup_reading`)
    at each height (the brightwind columns' names), UTC stamps at the period's start."""
    mast = pd.DataFrame({"Timestamp": table.index.strftime("%Y-%m-%d %H:%M")})
    for h, (speed, std, _) in MAST_COLUMNS.items():
        mean, deviation = cup_reading(table[f"speed_{h:g}"].to_numpy(),
                                      table[f"ti_{h:g}"].to_numpy(), scan_period)
        mast[speed], mast[std] = mean, deviation
    Path(folder).joinpath("mast.csv").write_text(
        mast.to_csv(index=False, float_format="%.6g"))


def cup_reading(speed, truth_ti, scan_period, duration=CAMPAIGN_RECORD_SECONDS):
    """(mean, standard deviation (ddof 1)) [m s-1] an ideal cup anemometer at a point of
    a record's field reads on average, sampled once a scan: the field of
    :func:`record_settings` (mean speed `speed` U along x, expected ten-minute TI
    `truth_ti` on the lidar's convention), arrays (n,); NaN where either is NaN.

    The cup reads ``c = |(U + u, v)|``, to second order in the fluctuations
    ``c = U + u + v^2 / (2 U)`` (the next terms dropped: the third-order
    ``-u v^2 / (2 U^2)`` has no mean for a Gaussian field, and the fourth-order mean,
    ``(sigma_v^2 sigma_u^2 / 2 - 3 sigma_v^4 / 8) / U^3``, is ~2 % of the share below at
    TI 0.4, the campaign's largest):

    * its mean ``U + sigma_v^2 / (2 U)``, sigma_v^2 the point v-variance of every scale
      (the record's slow part included: the cup takes the instantaneous vector's length);
    * its variance over the record ``V_u + (4 S_v R_v + 2 R_v^2) / (4 U^2)``, R_v the
      v-variance over the record (its high-pass), ``S_v = sigma_v^2 - R_v`` the slower part,
      Gaussian v: the record variance of ``v^2 = (v_s + v_r)^2`` is ``4 v_s^2 R_v`` (v_s
      held over the record) plus that of ``v_r^2``, taken as its whole variance ``2 R_v^2``
      (its part slower than the record, a small share of it, left in: under 1e-4 of
      the TI);
    * both with the records' N / (N - 1) of ``ddof`` 1; V_u = (TI U)^2 by construction.
    """
    from uq.physics.lidarspectral import record_filter
    from uq.physics.spectraltensor import MannTensor, point_spectra
    speed, truth_ti = (np.asarray(a, dtype=float) for a in (speed, truth_ti))
    n = int(np.floor(duration / scan_period + 1e-9))
    convention = n / (n - DDOF)
    # the spectra's shapes are the field's at any speed (the tensor's level, which the
    # mast's TI sets, cancels in the ratios below)
    k1, weights, spectra = point_spectra(MannTensor(TURBULENCE["length_scale"],
                                                    TURBULENCE["anisotropy"]))
    whole = weights @ spectra
    mean, deviation = np.full(speed.shape, np.nan), np.full(speed.shape, np.nan)
    for i in np.flatnonzero(np.isfinite(speed) & np.isfinite(truth_ti) & (speed > 0)):
        u_speed = float(speed[i])
        kept = (weights * record_filter(k1 * u_speed / (2 * np.pi), scan_period,
                                        duration)) @ spectra
        scale = (truth_ti[i] * u_speed) ** 2 / (kept[0] * convention)   # V_u's
        v_whole, v_record = whole[1] * scale, kept[1] * scale
        mean[i] = u_speed + v_whole / (2.0 * u_speed)
        slow = v_whole - v_record
        variance = kept[0] * scale + (4.0 * slow * v_record + 2.0 * v_record ** 2) \
            / (4.0 * u_speed ** 2)
        deviation[i] = np.sqrt(variance * convention)
    return mean, deviation
