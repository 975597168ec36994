"""uq report answers the question its run was made for, from the run's stored values:
a buoy's TI (record mode), a nacelle lidar's preview distance (a target on any output),
every output in the report, scene tables complete, options that do not apply refused."""
import html
import re

import numpy as np
import pytest

from tests.outputs.small_runs import small_result
from uq.cli import main
from uq.files import write_netcdf
from uq.outputs.report import render_report


def _cells(table_html):
    """The rows of an HTML table as lists of cell texts (tags stripped, unescaped)."""
    rows = re.findall(r"<tr>(.*?)</tr>", table_html, flags=re.S)
    return [[html.unescape(re.sub(r"<[^>]+>", "", cell))
             for cell in re.findall(r"<t[dh]>(.*?)</t[dh]>", row)] for row in rows]


def _section(page, level, title):
    """The HTML after the heading <h`level`> that contains `title`, up to the next
    heading of that level or higher."""
    match = re.search(rf"<h{level}>[^<]*{re.escape(title)}[^<]*</h{level}>", page)
    rest = page[match.end():]
    ends = [i for i in (rest.find(f"<h{n}>") for n in range(1, level + 1)) if i >= 0]
    return rest[:min(ends)] if ends else rest


def test_a_buoys_report_gives_the_records_ti_not_the_motion_added_in_quadrature():
    """The question "what TI does a buoy read": the report of a record-mode run gives the
    lidar's apparent TI from the spectral path and the records, beside the field's TI over
    a record it is compared with, each the stored value; the sum in quadrature (which
    leaves out the lidar's filtering) is not given."""
    ds = small_result("floating_lidar_ti")
    page = render_report(ds)
    assert "sum in quadrature" not in page
    table = _section(page, 3, "The turbulence intensity the lidar reads")
    header, *rows = _cells(table[table.index("<table>"):])
    assert header[:2] == ["turbulence.intensity", "correction"]
    column = {name: k for k, name in enumerate(header)}
    assert len(rows) == ds["turbulence_intensity_spectral"].size
    for row in rows:
        at = ds.sel(turbulence_intensity=float(row[0]), correction=row[1])
        for name, variable in (("field, over a record [%]", "turbulence_intensity_true"),
                               ("lidar, spectral [%]", "turbulence_intensity_spectral"),
                               ("lidar, records: mean [%]", "turbulence_intensity_mc_mean"),
                               ("records' field [%]", "turbulence_intensity_true_mc_mean")):
            assert row[column[name]] == f"{100 * float(at[variable]):.2f}", name
        assert row[column["field, point [%]"]] == f"{100 * float(row[0]):.2f}"


def test_a_nacelle_report_answers_which_preview_distances_keep_u_under_a_target():
    """The question "which preview distance does a nacelle lidar on a floating turbine
    need": a target on the wind speed's u gives, per correction model, the preview
    distances at which u stays under it (the stored u, Monte Carlo's), and the best one;
    the yaw misalignment and the shear exponent are reported too."""
    ds = small_result("nacelle_floating")
    u = ds["wind_speed_mc_u"]
    target = float(u.sel(correction="pointwise").median())
    page = render_report(ds, targets={"wind_speed": (target,)})
    answer = _section(page, 3, f"at or under {target:g} m/s")
    rows = {row[0]: row for row in _cells(answer[answer.index("<table>"):])[1:]}
    for correction in ("none", "pointwise"):
        at = u.sel(correction=correction)
        keeps = [f"{d:g}" for d, v in zip(at["range"].values, at.values) if v <= target]
        row = rows[f"correction = {correction}"]
        assert row[1] == f"{len(keeps)} of {at.size}"
        assert f"preview distance [m]: every scene {', '.join(keeps) or 'none'}" in row[2]
        best = at.isel(range=int(np.argmin(at.values)))
        assert row[3].startswith(f"{float(best):.4g} m/s at preview distance "
                                 f"{float(best['range']):g} m")
    for words in ("Yaw misalignment", "Shear exponent"):
        section = _section(page, 3, words)
        assert "Uncertainty budget" in section and "clause 8" in section


def test_the_scene_table_lists_every_gate():
    """All preview distances of every scene (it showed 3 of 9 without saying so)."""
    ds = small_result("nacelle_floating")
    page = render_report(ds)
    table = _section(page, 2, "Scene by scene")
    speed = table.split("<h3>Wind speed</h3>")[1].split("</table>")[0]
    rows = _cells(speed)[1:]
    assert len(rows) == ds.sizes["correction"] * ds.sizes["range"]


@pytest.mark.parametrize("arguments, problem", [
    (["--target", "turbulence_intensity=0.1"], "allowed: OUTPUT=U with OUTPUT one of"),
    (["--target", "wind_speed=-1"], "allowed: a positive number"),
    (["--true-ti", "8"], "does not apply"),
])
def test_options_that_do_not_apply_are_refused(tmp_path, capsys, arguments, problem):
    """A target on an output the run does not have, a negative target, and --true-ti on
    a run with records (whose TI the report gives) are refused with one line, exit 2."""
    path = write_netcdf(small_result("floating_lidar_ti"), tmp_path / "ti.nc")
    assert main(["report", str(path), "-q", *arguments]) == 2
    err = capsys.readouterr().err
    assert problem in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "ti_report.html").exists()


def test_a_target_on_any_output_is_answered_over_every_swept_key():
    """--target wind_direction=U on a sweep: per swept key the values that keep u under
    it in every scene (whatever the others) and in some scene, from the stored u."""
    ds = small_result("rubio2022_misalignment")
    u = ds["wind_direction_mc_u"]
    target = float(u.median())
    page = render_report(ds, targets={"wind_direction": (target,)})
    answer = _section(page, 3, f"at or under {target:g} deg")
    row = _cells(answer[answer.index("<table>"):])[1]
    assert row[1] == f"{int((u.values <= target).sum())} of {u.size}"
    for dim, key in (("ship_cog", "ship.cog"), ("wind_direction", "wind.direction")):
        others = [d for d in u.dims if d != dim]
        always = [f"{v:g}" for v, w in zip(u[dim].values, u.max(others).values)
                  if w <= target]
        assert f"{key}: every scene {', '.join(always) or 'none'}" in row[2]


def test_the_box_sentence_says_which_bands_the_records_drew():
    # from the file's stored shares alone: kept at 1 (the band larger than the box drawn
    # as a trend) says so; a file whose records left that band out (kept 0.99) says the
    # rest is missing; the box's own share is quoted in both
    import xarray as xr
    from uq.outputs.report import _box_sentence
    whole = _box_sentence(xr.Dataset({"turbulence_intensity_box_kept": 1.0,
                                      "turbulence_intensity_box_resolved": 0.94}))
    assert "0.94" in whole and "larger than the box as one slow trend" in whole
    assert "the rest" not in whole
    short = _box_sentence(xr.Dataset({"turbulence_intensity_box_kept": 0.991,
                                      "turbulence_intensity_box_resolved": 0.94}))
    assert "0.991" in short and "the rest: eddies longer than the box" in short
    assert "trend" not in short
