"""Error distributions of scenario files, as scipy.stats frozen distributions.

=============  ====================  =============================================
``dist``       parameters            distribution of the error
=============  ====================  =============================================
normal         u                     N(mean, u^2)
uniform        half_width            U(mean - a, mean + a); u = a / sqrt(3)
triangular     half_width            symmetric triangle on mean +- a; u = a / sqrt(6)
arcsine        amplitude             arcsine on mean +- A (a sinusoid of amplitude A
                                     sampled at a random phase); u = A / sqrt(2)
student_t      u, dof                scaled and shifted t with dof > 2 degrees of
                                     freedom and standard deviation u (scale
                                     u sqrt((dof - 2) / dof))
constant       value                 a known offset: the error is value + mean
=============  ====================  =============================================

Every error may carry ``mean`` (a bias, default 0). Units are those of the quantity the
error belongs to ([deg] for angles, [m s-1] for velocities). An error whose spread is zero
is a constant and is not sampled.

References
----------
.. [1] JCGM 101:2008, 6.4 (probability density functions for the input quantities).
"""
import functools
import math

from scipy import stats

ERROR_DISTRIBUTIONS = {
    "normal": ("u",),
    "uniform": ("half_width",),
    "triangular": ("half_width",),
    "arcsine": ("amplitude",),
    "student_t": ("u", "dof"),
    "constant": ("value",),
}
#: Smallest degrees of freedom with a finite variance, plus a margin [1].
MIN_STUDENT_DOF = 2.0


def validate_error(spec, key, check, extra=()):
    """Validated, normalised error specification (a dict with ``dist`` and ``mean``);
    `extra` names further keys the caller validates (e.g. ``correlation_time``)."""
    check.mapping(spec, key)
    dist = check.choice(spec.get("dist"), f"{key}.dist", tuple(ERROR_DISTRIBUTIONS))
    parameters = ERROR_DISTRIBUTIONS[dist]
    check.keys(spec, key, ("dist", "mean") + parameters + tuple(extra))
    out = {"dist": dist, "mean": check.number(spec.get("mean", 0.0), f"{key}.mean")}
    for name in parameters:
        if name not in spec:
            check.fail(f"{key}.{name}", f"missing; '{dist}' needs {', '.join(parameters)}")
        if name == "value":
            out[name] = check.number(spec[name], f"{key}.{name}")
        elif name == "dof":
            out[name] = check.number(spec[name], f"{key}.{name}", low=MIN_STUDENT_DOF,
                                     low_open=True)
        else:
            out[name] = check.number(spec[name], f"{key}.{name}", low=0.0)
    return out


def error_distribution(spec):
    """scipy.stats frozen distribution of a validated spec, or a float if it is constant.

    The same spec gives the same (shared, read-only) object: freezing a scipy
    distribution costs ~0.7 ms, which would be most of the fixed cost of a small run.
    """
    items = tuple(sorted(spec.items()))
    try:
        return _frozen(items)
    except TypeError:                        # an unhashable value: freeze it anew
        return _frozen.__wrapped__(items)


@functools.lru_cache(maxsize=1024)
def _frozen(items):
    spec = dict(items)
    dist, mean = spec["dist"], spec["mean"]
    if dist == "constant":
        return spec["value"] + mean
    spread = spec.get("u", spec.get("half_width", spec.get("amplitude")))
    if spread == 0:
        return mean
    if dist == "normal":
        return stats.norm(loc=mean, scale=spread)
    if dist == "uniform":
        return stats.uniform(loc=mean - spread, scale=2 * spread)
    if dist == "triangular":
        return stats.triang(c=0.5, loc=mean - spread, scale=2 * spread)
    if dist == "arcsine":
        return stats.arcsine(loc=mean - spread, scale=2 * spread)
    dof = spec["dof"]
    return stats.t(df=dof, loc=mean, scale=spread * math.sqrt((dof - 2) / dof))
