"""Words, units and styles shared by the figures and the report (no numbers, no I/O).

A figure names what it shows in words with units: a quantity ``u(wind speed) [m s-1]``,
a swept key ``wind direction [deg]``; the three models have one style everywhere, with
Monte Carlo drawn as markers on top of the lines, so that it stays visible where it
coincides with the GUM.
"""
#: Uncertainty variables: suffix -> (label, line style, marker). Monte Carlo is a marker
#: (drawn last, on top): where it equals the GUM, both stay visible.
MODELS = {"paper_u": ("Rubio & Gottschall (2022)", "-", None),
          "gum_u": ("GUM, physical model", "--", None),
          "mc_u": ("Monte Carlo, physical model", "", "o")}
#: Colours of the three models where colour does not encode something else.
MODEL_COLOURS = {"paper_u": "tab:blue", "gum_u": "tab:orange", "mc_u": "k"}
#: Quantities with their words, symbol and unit (as the axes show them).
QUANTITIES = {"wind_speed": ("wind speed", "$V_h$", "m s$^{-1}$"),
              "wind_direction": ("wind direction", r"$\Theta$", "deg"),
              "vertical_wind": ("vertical wind", "$w$", "m s$^{-1}$"),
              "radial_velocity": ("radial velocity", "$v_r$", "m s$^{-1}$"),
              "gate_height": ("gate height", "$z$", "m"),
              "yaw_misalignment": ("yaw misalignment", r"$\gamma$", "deg"),
              "shear_exponent": ("shear exponent", r"$\alpha$", "1")}
#: The quantities a figure of a sweep shows, in this order, when the result has them.
SWEEP_QUANTITIES = ("wind_speed", "wind_direction", "vertical_wind", "gate_height")
#: Requested outputs with a value per beam: a figure of their own (one panel per beam).
BEAM_QUANTITIES = ("radial_velocity",)
#: Words for the coordinates of swept scenario keys (others: the dotted key).
KEY_WORDS = {"wind_direction": "wind direction", "wind_speed": "wind speed",
             "wind_shear": "shear exponent", "wind_vertical": "vertical wind",
             "wind_reference_height": "reference height",
             "ship_cog": "ship course over ground", "ship_sog": "ship speed over ground",
             "ship_heading": "ship heading", "ship_pitch": "pitch (bow up +)",
             "ship_roll": "roll (starboard down +)", "ship_heave": "heave velocity",
             "lidar_misalignment": "lidar misalignment", "lidar_half_cone": "half-cone angle",
             "lidar_height": "lidar height", "range": "range gate (height above a level lidar)",
             "preview": "preview distance along the boresight"}
#: Units as the axes write them.
UNIT_TEXT = {"degree": "deg", "m s-1": "m s$^{-1}$", "m": "m", "1": "1"}


def quantity_label(quantity, what="u"):
    """``u(wind speed) [m s-1]``: a statistic of a quantity, in words with its unit."""
    words, _, unit = QUANTITIES[quantity]
    return f"{what}({words}) [{unit}]"


def coordinate_label(dataset, name):
    """A coordinate in words with its unit, e.g. ``wind direction [deg]``."""
    words = KEY_WORDS.get(name) or str(dataset[name].attrs.get("long_name", name)).replace(
        "swept scenario key ", "")
    units = dataset[name].attrs.get("units")
    return f"{words} [{UNIT_TEXT.get(units, units)}]" if units else words


def model_style(model):
    """Keyword arguments of matplotlib's plot for a model's line or markers."""
    label, line, marker = MODELS[model]
    style = {"label": label, "linestyle": line or "none", "color": MODEL_COLOURS[model]}
    if marker:
        style.update(marker=marker, markersize=4, markerfacecolor="none", zorder=5)
    return style
