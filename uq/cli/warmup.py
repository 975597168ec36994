"""``uq warmup``: compile every numba kernel into the on-disk cache ahead of the first run
(for people who build images or shared environments: run it once after the install, as
the user whose cache the runs will read)."""
from uq.cli.common import EXIT_OK, say


def add_parser(commands):
    warmup = commands.add_parser(
        "warmup", help="compile every kernel into numba's cache now (once after an "
        "install; for images and shared environments), so that no run compiles")
    warmup.set_defaults(handler=command)
    return warmup


def command(args):
    """Compile (or load, when already cached) every kernel of the static model in real
    and complex arithmetic, the time-resolved model's and the statistics'."""
    import time
    started = time.perf_counter()
    import numba
    import uq.engine.statkernels  # noqa: F401  (explicit signatures: compiled on import)
    import uq.engine.passkernels  # noqa: F401  (the same: long runs' one-pass batches)
    from uq.physics import fusedmotionkernels  # (the same)
    from uq.physics import turbulencekernels  # noqa: F401  (record mode's: the same)
    from uq.physics import fusedkernels
    for number in (float, complex):
        for name in fusedkernels.KERNEL_NAMES:
            if number is float or name not in fusedkernels.MOUNTED_KERNEL_NAMES:
                fusedkernels.compiled(number)[name]
    fusedmotionkernels.compiled_mounted_wind()        # a tilted mount's, on first use
    compiling = getattr(args, "compile_notice", None)
    compiled = compiling.kernels if compiling else 0
    say(args, f"uq warmup: {compiled} kernel(s) compiled, the others loaded from the cache "
        f"({numba.config.CACHE_DIR or 'beside the code'}), {time.perf_counter() - started:.1f} s")
    return EXIT_OK
