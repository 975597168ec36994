"""CF attributes and netCDF encodings of the result variables (CF conventions 1.10).

Standard names are from the CF standard-name table; uncertainties use the CF modifier
``standard_error`` (CF conventions 1.10, Appendix C). What a file needs beyond the
attributes of each variable, for every writer of the tool (:func:`cf_encode`):

* coordinate variables carry no ``_FillValue`` and no missing value (CF 2.5.1);
* string-valued coordinates (``input``, ``fit``, ``parameter``, ...) are stored as
  character arrays, so that no string-valued variable is taken for a numeric coordinate
  variable (CF 2.2, 5; xarray reads them back as strings);
* booleans are CF flag variables: ``flag_values`` 0 and 1, ``flag_meanings`` (CF 3.5);
* a ``history`` line says what wrote the file (CF 2.6.2, :func:`history`).

Beams (dimension ``beam``): the beam number 0, 1, ... (the slanted beams in the order of
``lidar.azimuths``, then the vertical beam), with the auxiliary coordinates
``beam_azimuth`` (clockwise from the lidar's reference beam; missing for the vertical
beam, whose azimuth is undefined: CF allows missing values in an auxiliary coordinate)
and ``beam_vertical`` (a flag).
"""
import datetime

import numpy as np

from uq._version import __version__
from uq.physics.modelinputs import error_units

QUANTITIES = {
    "wind_speed": {"units": "m s-1", "long_name": "horizontal wind speed",
                   "standard_name": "wind_speed"},
    "wind_direction": {"units": "degree", "long_name": "wind direction (from, clockwise from north)",
                       "standard_name": "wind_from_direction"},
    "vertical_wind": {"units": "m s-1", "long_name": "vertical wind (positive up)",
                      "standard_name": "upward_air_velocity"},
    "radial_velocity": {"units": "m s-1",
                        "long_name": "motion-corrected radial velocity (positive away from the lidar)",
                        "standard_name": "radial_velocity_of_scatterers_away_from_instrument"},
    "gate_height": {"units": "m", "long_name": "height above sea level of the range gate "
                    "(mean of the slanted beams' true heights)", "standard_name": "height_above_mean_sea_level"},
    "yaw_misalignment": {"units": "degree", "long_name": "yaw misalignment: wind direction "
                         "(from) minus the rotor axis (ship.heading), clockwise, in [-180, 180)"},
    "shear_exponent": {"units": "1", "long_name": "power-law shear exponent from the upper and "
                       "lower beams of a nacelle lidar (w = 0 assumed)"},
}

STATISTICS = {
    "true": ("true value in the scene", None),
    "nominal": ("reconstruction with every error zero", None),
    "gum_value": ("GUM estimate: model at the input means", None),
    "mc_mean": ("Monte Carlo mean", None),
    "mc_bias": ("Monte Carlo mean minus true value", None),
    "probe_bias": ("systematic error of the probe volume: reconstruction with every error "
                   "zero, range-weighted along the beams, minus the same at the gate centres "
                   "(a part of nominal minus true)", None),
    "mc_u": ("Monte Carlo standard uncertainty", "standard_error"),
    "mc_low": ("lower end of the 95 % coverage interval (Monte Carlo)", None),
    "mc_high": ("upper end of the 95 % coverage interval (Monte Carlo)", None),
    "mc_circular_std": ("Monte Carlo circular standard deviation sqrt(-2 ln R)", None),
    "mc_numerical_error": ("numerical error of the Monte Carlo results: the largest standard "
                           "error of mean, u and interval ends over independent batches (at "
                           "least 32 in a fixed-n run) times max(2, Student t 97.5 % of the "
                           "batches' degrees of freedom) (JCGM 101 7.9)", None),
    "mc_numerical_tolerance": ("numerical tolerance of the requested significant digits "
                               "(JCGM 101 7.9.2)", None),
    "mc_u_standard_error": ("standard error of the Monte Carlo standard uncertainty, from "
                            "its spread over independent batches (at least 32 in a fixed-n "
                            "run of 2^15 trials or more)", None),
    "mc_n_invalid": ("Monte Carlo trials outside the model's domain (non-finite, excluded)", None),
    "gum_u": ("first-order GUM standard uncertainty of the physical model", "standard_error"),
    "gum_valid": ("GUM interval validated by Monte Carlo (JCGM 101 clause 8)", None),
    "gum_validation_conclusive": ("Monte Carlo numerical error within the tolerance of the "
                                  "validation, so gum_valid is conclusive", None),
    "gum_validation_tolerance": ("tolerance delta of the JCGM 101 clause 8 validation: half "
                                 "a unit of the last of the validation's significant digits "
                                 "of the GUM u (JCGM 101 7.9.2, 8.2)", None),
    "paper_u": ("Rubio and Gottschall (2022) analytic standard uncertainty", "standard_error"),
    "budget": ("contribution of each input to the GUM variance, c_i^2 u_i^2", None),
    "mc_covariance": ("Monte Carlo covariance between range gates", None),
    "gum_covariance": ("first-order GUM covariance between range gates, J V J^T", None),
}

SQUARED_UNITS = {"m s-1": "m2 s-2", "degree": "degree2", "m": "m2", "1": "1"}


def variable_attributes(quantity, statistic):
    """Attributes of ``{quantity}_{statistic}``."""
    base = QUANTITIES[quantity]
    long_name, modifier = STATISTICS[statistic]
    attrs = {"long_name": f"{base['long_name']}: {long_name}"}
    if statistic == "mc_n_invalid":
        attrs["units"] = "1"
    elif statistic in ("budget", "mc_covariance", "gum_covariance"):
        attrs["units"] = SQUARED_UNITS[base["units"]]
    elif statistic in FLAG_MEANINGS:
        attrs.update(flag_attributes(FLAG_MEANINGS[statistic]))
    else:
        attrs["units"] = base["units"]
    if "standard_name" not in base:          # (no CF name: yaw misalignment, shear exponent)
        return attrs
    if statistic in ("true", "nominal", "gum_value", "mc_mean"):
        attrs["standard_name"] = base["standard_name"]
    elif modifier:
        attrs["standard_name"] = f"{base['standard_name']} {modifier}"
    return attrs


COORDINATES = {
    "range": {"units": "m", "long_name": "range-gate height above a level lidar"},
    "range_other": {"units": "m", "long_name": "range-gate height above a level lidar "
                    "(second index of a covariance)"},
    "beam": {"long_name": "beam number: the slanted beams in the order of lidar.azimuths, "
             "then the vertical beam"},
    "beam_azimuth": {"units": "degree", "long_name": "beam azimuth, clockwise from the "
                     "lidar's reference beam (missing for the vertical beam)"},
    "beam_vertical": {"long_name": "the beam is the vertical beam",
                      "flag_values": np.array([0, 1], dtype=np.int8),
                      "flag_meanings": "slanted vertical"},
    "input": {"long_name": "uncertain input (dotted scenario key)"},
}

#: flag_meanings of the boolean statistics (false first, then true).
FLAG_MEANINGS = {"gum_valid": "not_validated validated",
                 "gum_validation_conclusive": "inconclusive conclusive"}
#: Units of the scenario's own unit names (docs/scenario.md) in UDUNITS, as CF wants.
SCENARIO_UNITS = {"deg": "degree", "m s-1": "m s-1", "m": "m", "1": "1", "um": "um",
                  "mm": "mm"}
#: Parameters of an error distribution that are numbers without unit.
DIMENSIONLESS_PARAMETERS = ("dof",)
#: Statistics linked to their quantity's Monte Carlo mean and GUM value
#: (``ancillary_variables``, CF 3.4): the interval's ends, uncertainties and diagnostics.
ANCILLARY = {"mc_mean": ("mc_low", "mc_high", "mc_u", "mc_u_standard_error",
                         "mc_numerical_error", "mc_numerical_tolerance", "mc_n_invalid",
                         "mc_circular_std", "mc_covariance"),
             "gum_value": ("gum_u", "gum_valid", "gum_validation_conclusive",
                           "gum_validation_tolerance", "budget",
                           "gum_covariance")}


#: The turbulence intensities of record mode, one name each: TI name -> (name, what it
#: is). The report (:mod:`uq.outputs.report`), the summary's legend and the netCDF
#: attributes (:func:`turbulence_intensity_attributes`) say the same words.
TI_NAMES = {
    "turbulence.intensity": ("the field's point TI", "the scenario's input: sigma_u / U of "
                             "the field at the reference point, over all time scales"),
    "turbulence_intensity_true": ("the field's TI over a record", "what a ten-minute "
                                  "record of the field at the reference point shows (its "
                                  "slowest eddies fall outside the record): the TI the "
                                  "lidar's is compared with"),
    "turbulence_intensity_spectral": ("the lidar's apparent TI, spectral", "expected from "
                                      "the spectral path: the filtered turbulence and each "
                                      "scan's errors"),
    "turbulence_intensity_mc_mean": ("the lidar's apparent TI, records", "the mean over the "
                                     "Monte Carlo records (with the 2.5 and 97.5 % points "
                                     "of the records)"),
    "turbulence_intensity_true_mc_mean": ("the records' field TI", "the field's TI over a "
                                          "record in those Monte Carlo records: what the "
                                          "records' apparent TI is compared with"),
}
#: Each record-mode variable (and the swept coordinate of ``turbulence.intensity``) ->
#: the TI of :data:`TI_NAMES` it is or is a statistic of, and its wind component.
TI_VARIABLES = {
    "turbulence_intensity": ("turbulence.intensity", None),
    "turbulence_intensity_true": ("turbulence_intensity_true", None),
    "turbulence_intensity_true_error": ("turbulence_intensity_true", None),
    "turbulence_intensity_v_true": ("turbulence_intensity_true", "lateral, v"),
    "turbulence_intensity_w_true": ("turbulence_intensity_true", "vertical, w"),
    "turbulence_intensity_spectral": ("turbulence_intensity_spectral", None),
    "turbulence_intensity_spectral_error": ("turbulence_intensity_spectral", None),
    "turbulence_intensity_spectral_turbulence": ("turbulence_intensity_spectral", None),
    "turbulence_intensity_v_spectral": ("turbulence_intensity_spectral", "lateral, v"),
    "turbulence_intensity_w_spectral": ("turbulence_intensity_spectral", "vertical, w"),
    "turbulence_intensity_mc_mean": ("turbulence_intensity_mc_mean", None),
    "turbulence_intensity_mc_u": ("turbulence_intensity_mc_mean", None),
    "turbulence_intensity_mc_low": ("turbulence_intensity_mc_mean", None),
    "turbulence_intensity_mc_high": ("turbulence_intensity_mc_mean", None),
    "turbulence_intensity_v_mc_mean": ("turbulence_intensity_mc_mean", "lateral, v"),
    "turbulence_intensity_w_mc_mean": ("turbulence_intensity_mc_mean", "vertical, w"),
    "turbulence_intensity_true_mc_mean": ("turbulence_intensity_true_mc_mean", None),
    "turbulence_intensity_v_true_mc_mean": ("turbulence_intensity_true_mc_mean",
                                            "lateral, v"),
    "turbulence_intensity_w_true_mc_mean": ("turbulence_intensity_true_mc_mean",
                                            "vertical, w"),
}


def turbulence_intensity_attributes(variable, attributes):
    """`attributes` (a dict with a ``long_name``) of a turbulence-intensity `variable` of
    :data:`TI_VARIABLES` with its one name: the ``long_name`` led by the name (``"the
    field's TI over a record: ..."``; a v or w component's said after it) and a
    ``comment`` with the name and what it is (:data:`TI_NAMES`). Other variables'
    attributes are returned unchanged."""
    if variable not in TI_VARIABLES:
        return dict(attributes)
    key, component = TI_VARIABLES[variable]
    name, meaning = TI_NAMES[key]
    named = name if component is None else f"{name} ({component})"
    return {**attributes, "long_name": f"{named}: {attributes['long_name']}",
            "comment": f"{name}: {meaning}"}


def swept_key_attributes(key, linked_to=None):
    """long_name and units (where it has one) of the coordinate of a swept scenario key
    (``wind.direction`` -> ``wind_direction``), or of a key linked to one."""
    long_name = f"swept scenario key {key}" if linked_to is None else \
        f"scenario key {key}, linked to the swept key {linked_to}"
    units = scenario_key_units(key)
    return turbulence_intensity_attributes(
        key.replace(".", "_") if key in TI_NAMES else None,
        {"long_name": long_name, **({"units": units} if units else {})})


def scenario_key_units(key):
    """UDUNITS units of a dotted scenario key, or None (a choice, a text, a flag)."""
    from uq.pipeline.reference import meaning
    parts = key.split(".")
    if parts[0] in ("ins", "lidar") and len(parts) >= 3 and \
            (parts[0] == "ins" or parts[1] == "errors"):
        quantity, parameter = parts[-2], parts[-1]
        if parameter in DIMENSIONLESS_PARAMETERS:
            return "1"
        return error_units().get(quantity)      # (:mod:`uq.physics.modelinputs`)
    found = meaning(key)
    return SCENARIO_UNITS.get(found[0]) if found else None


def ancillary_variables(dataset, quantity):
    """``{name: "space-separated ancillary names"}`` for the Monte Carlo mean and the
    GUM value of `quantity` (only the statistics the Dataset has)."""
    links = {}
    for head, statistics in ANCILLARY.items():
        names = [f"{quantity}_{s}" for s in statistics if f"{quantity}_{s}" in dataset]
        if f"{quantity}_{head}" in dataset and names:
            links[f"{quantity}_{head}"] = " ".join(names)
    return links


def flag_attributes(meanings="false true"):
    """Attributes of a boolean stored as a CF flag variable (0 = false, 1 = true)."""
    return {"flag_values": np.array([0, 1], dtype=np.int8), "flag_meanings": meanings}


def cf_encode(dataset):
    """Make `dataset` ready for a CF netCDF file, in place (see the module docstring):
    no ``_FillValue`` on coordinates, string coordinates as character arrays, booleans
    as flag variables (a long_name from the name where none is set). Returns it."""
    for name, variable in dataset.variables.items():
        if name in dataset.coords:          # a missing value only where one is missing
            missing = name not in dataset.dims and variable.dtype.kind == "f" and \
                bool(np.isnan(variable.values).any())
            variable.encoding["_FillValue"] = np.nan if missing else None
            if variable.dtype.kind in "OUS":
                variable.encoding["dtype"] = "S1"
        if variable.dtype == bool:
            variable.attrs.pop("units", None)          # a flag has no unit (CF 3.5)
            if "flag_values" not in variable.attrs:
                variable.attrs.update(flag_attributes())
            variable.attrs.setdefault("long_name", name.replace("_", " "))
    return dataset


def history(command):
    """One line of the CF ``history`` attribute: UTC time, the tool and what it did."""
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
    return f"{now} uq {__version__}: {command}"
