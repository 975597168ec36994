"""``uq warmup``: compile every numba kernel into the on-disk cache ahead of the first run
(for people who build images or shared environments: run it once after the install, as
the user whose cache the runs will read)."""
from uq.cli.common import EXIT_OK, add_overrides, say


def add_parser(commands):
    warmup = commands.add_parser(
        "warmup", help="compile every kernel into numba's cache now (once after an "
        "install; for images and shared environments), so that no run compiles")
    warmup.add_argument("--for", dest="scenario", metavar="SCENARIO",
                        help="compile only what a run of this scenario (YAML file or "
                        "shipped name) calls: its per-scan Monte Carlo, a few trials per "
                        "scene, results discarded (its turbulence records are left out)")
    add_overrides(warmup, "a value of the --for scenario, as in uq run (only with --for)")
    warmup.set_defaults(handler=command)
    return warmup


def command(args):
    """Compile (or load, when already cached) every kernel of the static model in real
    and complex arithmetic, the time-resolved model's and the statistics' (or, with
    ``--for``, those a run of one scenario calls)."""
    import time
    if getattr(args, "set", None) and not getattr(args, "scenario", None):
        from uq.errors import ScenarioError
        key = args.set[0].partition("=")[0]
        raise ScenarioError("--set/--unset", key, "applies only to the scenario of --for "
                            "(without it every kernel is compiled, no scenario is read); "
                            "allowed: uq warmup --for SCENARIO --set KEY=VALUE, or no --set")
    started = time.perf_counter()
    if getattr(args, "scenario", None):
        compile_for(args.scenario, getattr(args, "set", []))
        return _said(args, started)
    import uq.engine.statkernels  # noqa: F401  (explicit signatures: compiled on import)
    import uq.engine.passkernels  # noqa: F401  (the same: long runs' one-pass batches)
    from uq.physics import fusedmotionkernels  # (the same)
    compile_record_kernels()                          # record mode's (the same)
    from uq.physics import fusedkernels
    for number in (float, complex):
        for name in fusedkernels.KERNEL_NAMES:
            if number is float or name not in fusedkernels.REAL_KERNEL_NAMES:
                fusedkernels.compiled(number)[name]
    fusedmotionkernels.compiled_mounted_wind()        # a tilted mount's, on first use
    return _said(args, started)


def _said(args, started):
    """Say what was compiled and where it is kept; the exit status."""
    import time
    import numba
    compiling = getattr(args, "compile_notice", None)
    compiled = compiling.kernels if compiling else 0
    say(args, f"uq warmup: {compiled} kernel(s) compiled, the others loaded from the cache "
        f"({numba.config.CACHE_DIR or 'beside the code'}), {time.perf_counter() - started:.1f} s")
    return EXIT_OK


def compile_for(scenario, overrides=()):
    """Run `scenario` (a path, a shipped name or a mapping) with ``--set`` `overrides`
    without its turbulence records (the ``turbulence`` and ``record`` sections and their
    sweep keys), :data:`~uq.cli.sidecompile.SIDE_COMPILE_TRIALS` trials per scene, the
    results discarded: numba compiles (or loads) every kernel of its per-scan Monte
    Carlo, the GUM's and the statistics' (those of runs of 2^17 trials or more too,
    which a run of a few trials does not call). A record-mode run's own records then
    call the same kernels (:mod:`uq.cli.sidecompile`); its boxes' and spectral path's
    kernels are compiled first (:func:`compile_record_kernels`)."""
    import copy
    import logging
    from uq.cli.common import parse_overrides
    from uq.cli.sidecompile import SIDE_COMPILE_TRIALS
    from uq.pipeline.runner import run
    from uq.pipeline.scenario import load_scenario
    from uq.pipeline.shipped import scenario_path
    if not isinstance(scenario, dict):
        scenario = scenario_path(scenario)
    settings = copy.deepcopy(load_scenario(scenario, parse_overrides(overrides)).settings)
    if record_mode(settings):
        compile_record_kernels()             # first: a first run waits on numpy for them
    for section in RECORD_SECTIONS:
        settings.pop(section, None)
    sweep = {key: values for key, values in (settings.pop("sweep", None) or {}).items()
             if key.split(".")[0] not in RECORD_SECTIONS}
    settings.update({"sweep": sweep} if sweep else {})
    settings["sampling"] = {**settings["sampling"], "n": SIDE_COMPILE_TRIALS}
    logging.disable(logging.WARNING)    # the stripped scenario's warnings are not the user's
    try:
        run(load_scenario(settings))
    finally:
        logging.disable(logging.NOTSET)
    import uq.engine.passkernels  # noqa: F401  (long runs' statistics: compiled on import)


def compile_record_kernels():
    """Compile (or load) the kernels a record-mode run calls outside its chunks' model:
    its boxes' colouring and sampling, the spectral path's sums (explicit signatures:
    compiled on import)."""
    import uq.physics.turbulencekernels  # noqa: F401
    import uq.physics.spectralkernels  # noqa: F401


#: The sections of record mode (:mod:`uq.pipeline.records`), left out by :func:`compile_for`.
RECORD_SECTIONS = ("turbulence", "record")


def record_mode(settings):
    """Whether scenario `settings` (a mapping) has a section of record mode."""
    return any(section in settings for section in RECORD_SECTIONS)
