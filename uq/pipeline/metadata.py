"""CF-style attributes of the result variables (units, long_name, standard_name).

Standard names are from the CF standard-name table; uncertainties use the CF modifier
``standard_error`` (CF conventions 1.10, Appendix C).
"""

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
}

STATISTICS = {
    "true": ("true value in the scene", None),
    "nominal": ("reconstruction with every error zero", None),
    "gum_value": ("GUM estimate: model at the input means", None),
    "mc_mean": ("Monte Carlo mean", None),
    "mc_bias": ("Monte Carlo mean minus true value", None),
    "mc_u": ("Monte Carlo standard uncertainty", "standard_error"),
    "mc_low": ("lower end of the 95 % coverage interval (Monte Carlo)", None),
    "mc_high": ("upper end of the 95 % coverage interval (Monte Carlo)", None),
    "mc_circular_std": ("Monte Carlo circular standard deviation sqrt(-2 ln R)", None),
    "mc_numerical_error": ("numerical error of the Monte Carlo results: twice the standard "
                           "deviation of batch averages (JCGM 101 7.9)", None),
    "mc_numerical_tolerance": ("numerical tolerance of the requested significant digits "
                               "(JCGM 101 7.9.2)", None),
    "mc_u_standard_error": ("standard error of the Monte Carlo standard uncertainty, from "
                            "its spread over independent batches", None),
    "mc_n_invalid": ("Monte Carlo trials outside the model's domain (non-finite, excluded)", None),
    "gum_u": ("first-order GUM standard uncertainty of the physical model", "standard_error"),
    "gum_valid": ("GUM interval validated by Monte Carlo (JCGM 101 clause 8)", None),
    "gum_validation_conclusive": ("Monte Carlo numerical error within the tolerance of the "
                                  "validation, so gum_valid is conclusive", None),
    "paper_u": ("Rubio and Gottschall (2022) analytic standard uncertainty", "standard_error"),
    "budget": ("contribution of each input to the GUM variance, c_i^2 u_i^2", None),
    "mc_covariance": ("Monte Carlo covariance between range gates", None),
    "gum_covariance": ("first-order GUM covariance between range gates, J V J^T", None),
}

SQUARED_UNITS = {"m s-1": "m2 s-2", "degree": "degree2", "m": "m2"}


def variable_attributes(quantity, statistic):
    """Attributes of ``{quantity}_{statistic}``."""
    base = QUANTITIES[quantity]
    long_name, modifier = STATISTICS[statistic]
    attrs = {"long_name": f"{base['long_name']}: {long_name}"}
    if statistic == "mc_n_invalid":
        attrs["units"] = "1"
    elif statistic in ("budget", "mc_covariance", "gum_covariance"):
        attrs["units"] = SQUARED_UNITS[base["units"]]
    elif statistic not in ("gum_valid", "gum_validation_conclusive"):
        attrs["units"] = base["units"]
    if statistic in ("true", "nominal", "gum_value", "mc_mean"):
        attrs["standard_name"] = base["standard_name"]
    elif modifier:
        attrs["standard_name"] = f"{base['standard_name']} {modifier}"
    return attrs


COORDINATES = {
    "range": {"units": "m", "long_name": "range-gate height above a level lidar"},
    "range_other": {"units": "m", "long_name": "range-gate height above a level lidar "
                    "(second index of a covariance)"},
    "beam": {"units": "degree", "long_name": "beam azimuth from the reference beam "
             "(clockwise; vertical beam: NaN)"},
    "input": {"long_name": "uncertain input (dotted scenario key)"},
}
