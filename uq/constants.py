"""Named constants, each with its unit and source.

Nothing else in the package writes a bare number that carries meaning.
"""
import math

#: Coverage probability of the reported coverage intervals [1]. JCGM 101:2008, 7.7.
COVERAGE_PROBABILITY = 0.95

#: Default number of significant decimal digits for the numerical tolerance [1].
#: JCGM 101:2008, 7.9.2 and 8.2 (n_dig = 2 is the usual choice).
DEFAULT_DIGITS = 2

#: Samples per random-number block [1]. Every block has its own independent stream
#: (``numpy.random.SeedSequence`` spawn key = block index), which is what makes results
#: independent of the chunk size. A power of two so that Sobol' blocks stay balanced, and
#: >= 10^4 = max(100 / (1 - p), 10^4), the batch size of JCGM 101:2008, 7.9.4 a).
RNG_BLOCK_SIZE = 2**16

#: Samples per batch of the batch statistics that estimate the numerical error of the
#: Monte Carlo results (JCGM 101:2008, 7.9.4 uses batches of M >= 10^4). Divides
#: RNG_BLOCK_SIZE, so batches never straddle blocks.
BATCH_SIZE = 2**14

#: Fewest batches the standard errors of a fixed-n Monte Carlo run rest on [1]: the
#: standard deviation of h batch values has a relative error of about 1 / sqrt(2 (h - 1)),
#: 13 % at h = 32 (against 32 % at the 6 batches of 2^14 in 10^5 trials), and Student's
#: t_{0.975}(h - 1) = 2.04 is within 4 % of the normal 1.96. Below 32 x BATCH_SIZE trials
#: the batches of the standard errors are smaller than BATCH_SIZE (a power of two).
STANDARD_ERROR_BATCHES = 32

#: Smallest batch of the standard errors [trials] [1]: its 2.5 % and 97.5 % quantiles
#: lie ~25 order statistics in from the ends, so a batch's coverage interval is defined
#: (>= 1 / (1 - p) = 20 values, JCGM 101 7.2.2) and near its large-sample distribution.
MIN_STANDARD_ERROR_BATCH = 2**10

#: Default number of blocks evaluated together in one chunk [1]. Bounds memory: the lidar
#: model holds a few dozen float64 arrays of (chunk, beams, gates) at a time. One block:
#: the next chunk's draws overlap this one's evaluation from 2^16 trials on.
DEFAULT_BLOCKS_PER_CHUNK = 1

#: Largest number of Monte Carlo trials adaptive sampling (``digits``) may use [1].
ADAPTIVE_MAX_SAMPLES = 2**24

#: Most negative eigenvalue, per row, of a correlation matrix taken as positive
#: semidefinite [1] (:func:`uq.engine.inputs.semidefinite_root`): a correlation matrix
#: computed in double precision carries errors of ~1e-16 per element, which move its
#: eigenvalues by at most n x that (Weyl); 1e-12 leaves a margin of 1e4, while
#: inconsistent correlations give negative eigenvalues of the order of the coefficients.
SEMIDEFINITE_TOLERANCE = 1e-12

#: Complex-step size, relative to max(1, |x|) [1]. Complex-step differentiation has no
#: subtractive cancellation, so any step far below sqrt(machine epsilon) times the
#: curvature scale gives the derivative to machine precision (Squire & Trapp 1998);
#: 1e-30 leaves a margin of ~20 orders and is far above the smallest normal double.
COMPLEX_STEP = 1e-30

#: Full circle [deg].
FULL_CIRCLE_DEG = 360.0

#: Half circle [deg]: the unwrapping window of circular outputs is reference +- this.
HALF_CIRCLE_DEG = 180.0

#: Trial x scene x beam x gate elements of one vectorised sweep evaluation [1]. With a
#: few dozen float64 (or complex, for the GUM) temporaries of that size alive at once,
#: 2^20 keeps one evaluation near 200 MB, and large enough that the per-call overhead
#: (~1 ms) is small against the arithmetic.
SWEEP_CHUNK_ELEMENTS = 2**20

#: Trial x scene x gate x output values of one sweep evaluation by the compiled model
#: [1] (:mod:`uq.physics.fused`: it holds no per-beam temporaries): 2^22 doubles = 32 MB of
#: outputs, a few times that in the statistics' copies. Fewer, larger chunks draw the
#: shared random numbers fewer times (a 2^16-trial sweep of floating_lidar_full: 7
#: scenes per chunk instead of 1).
SWEEP_CHUNK_ELEMENTS_COMPILED = 2**22

#: Most scenes of one chunk of a Monte Carlo sweep [1] (:func:`uq.pipeline.sweep.
#: scenes_per_chunk`): the compiled model evaluates any number of scenes in one call
#: (:mod:`uq.physics.fused`), so this bounds the chunk's outputs and statistics instead.
FUSED_MAX_SCENES = 64

#: Fewest scenes of a complex-step call (the GUM's Jacobian) that the compiled static
#: model takes [1] (:func:`uq.physics.fused.declined`); smaller calls run the numpy
#: model's complex step. Measured (numba 0.68, 2 cores): the numpy complex step costs
#: ~12 us per scene, the compiled one ~2.4 us once compiled, and compiling its complex
#: kernels ~11 s of a cold start (of 27 s for ``uq run rubio2022_case_i``). Below 2^14
#: scenes the compiled kernels save under 0.2 s a run: a one-scene case, or a Monte Carlo
#: sweep's chunk (at most :data:`FUSED_MAX_SCENES` scenes) never compiles them, a GUM
#: grid (Rubio & Gottschall's Fig. 2: 518,400 scenes) does. The two complex steps agree
#: to 1e-12 (tests/physics/test_fused.py).
COMPLEX_STEP_COMPILED_MIN_SCENES = 2**14

#: von Karman constant [1]: 0.40, the value of Hogstrom (1996), Boundary-Layer
#: Meteorol. 78, 215-246 (0.40 +- 0.01 from his review of surface-layer experiments).
VON_KARMAN = 0.40

#: Fewest emcee walkers of a profile fit [1]: at least 32 by the project's own rule; the
#: affine-invariant ensemble needs more than twice the parameters (here <= 3).
MIN_WALKERS = 32

#: Most emcee walkers of a profile fit [1]: 32 times the fewest; more walkers of three
#: parameters only slow each step.
MAX_WALKERS = 1024

#: Most independent ensembles of a profile fit [1]: the R-hat of 4 (the default) is
#: already reliable (Vehtari et al. 2021); each costs a full chain.
MAX_ENSEMBLES = 64

#: Most steps per ensemble of a profile fit (``fit.max_steps``) [1].
MAX_FIT_STEPS = 1_000_000

#: Most draws (walkers x ensembles x max_steps) a fit may keep [1]: the chains are held in
#: memory (8 bytes x 3-4 parameters each, then a converted copy): 10^7 draws are ~0.7 GB
#: at most, 1.6 times the default 32 x 4 x 50000.
MAX_FIT_DRAWS = 10_000_000

# --- golden-lidar verification (uq.golden) -------------------------------------------

#: Width of the reference-wind-speed bins [m s-1]; bins are centred on multiples of it.
#: IEC 61400-12-1:2017 Annex L, and Coll-Vinent & Miquel (FLS200 golden lidar).
GOLDEN_BIN_WIDTH = 0.5

#: Reference-speed range whose bins must each hold enough records [m s-1] (bin centres,
#: inclusive). IEC 61400-12-1:2017 Annex L calibration range.
GOLDEN_REQUIRED_RANGE = (4.0, 16.0)

#: Fewest 10-min records a bin in the required range needs [1].
GOLDEN_MIN_RECORDS = 6

#: Largest plausible 10-min mean wind speed [m s-1]: above the strongest recorded 10-min
#: means (tropical cyclones, ~80 m/s); a larger value is a missing-value code or a unit
#: mistake. Bounds the records and ``golden.bins.required``.
GOLDEN_MAX_SPEED = 100.0

#: Most reference-speed bins of a campaign [1]: 0 to GOLDEN_MAX_SPEED in 0.1 m/s bins;
#: the bins are built before any record is counted (memory and time follow their number).
GOLDEN_MAX_BINS = 1000

#: Level of the two-sided t-test on a sensitivity slope [1]: a slope is significant when
#: its p-value is below this (the conventional 5 %).
GOLDEN_SIGNIFICANCE = 0.05

#: Floating-lidar acceptance KPIs, (best practice, minimum), Carbon Trust OWA roadmap as
#: reproduced in IEA Wind RP 18. Slopes are bands around 1, R^2 lower bounds,
#: the direction offset an upper bound on |offset| [deg].
KPI_SPEED_SLOPE = ((0.98, 1.02), (0.97, 1.03))
KPI_SPEED_R2 = (0.98, 0.97)
KPI_DIRECTION_SLOPE = ((0.97, 1.03), (0.95, 1.05))
KPI_DIRECTION_OFFSET_DEG = (5.0, 10.0)
KPI_DIRECTION_R2 = (0.97, 0.95)

#: Availability KPI (best practice, minimum) [1]: the OWA roadmap's overall
#: post-processed data availability. Configurable (``golden.kpi.availability``): check it
#: against the roadmap version a report is written to.
KPI_AVAILABILITY = (0.90, 0.85)

#: Fraction of the numerical tolerance delta to which Monte Carlo results are taken when
#: they validate the GUM [1]: JCGM 101:2008, 8.2 (results for validation to delta / 5).
VALIDATION_TOLERANCE_FRACTION = 0.2

#: Range of sqrt(x^2 + y^2) [any unit] inside which the plain formula is used for a
#: hypotenuse: the squares stay normal doubles (1e-300 .. 1e300, DBL_MIN = 2.2e-308,
#: DBL_MAX = 1.8e308), so it is exact to an ulp or two (IEEE 754); outside, numpy.hypot.
HYPOT_SAFE_MIN, HYPOT_SAFE_MAX = 1e-150, 1e150

#: Random values per call of the model inside a chunk [1] (trials x input dimension,
#: :func:`uq.propagate.model_slice_size`). The model's intermediate arrays (e.g. the
#: heights of 5 beams x 3 gates per trial) then stay in the L2 cache instead of streaming
#: through memory. Measured on floating_lidar_full (23 inputs, 2^17 trials): 105 ms in
#: one call, 84 ms in slices of 2^13 trials, slower again at 2^11 (per-call overhead);
#: a 4-input scan scene is fastest with whole 2^16 blocks.
MODEL_SLICE_VALUES = 2**18

#: Output values per statistic kept whole before only the tails are kept [1]
#: (:class:`uq.engine.statistics.StreamingStatistics`): 2^23 doubles = 64 MB. Below it the
#: interval endpoints come from one partition at the end (exact, the same order
#: statistics), which is ~3x cheaper than maintaining the tails batch by batch; above it
#: memory stays bounded (10^8 trials).
STORED_VALUES = 2**23
#: Trials of a run from which its statistics take each batch in one compiled pass with
#: the run's brackets (:mod:`uq.engine.passkernels`: at 2^19 trials of
#: ``floating_lidar_full`` the statistics cost half as much CPU); below it the kernels of
#: :mod:`uq.engine.statkernels` alone, so that the shipped scenarios (at most 10^5 trials)
#: and a cold start do not compile the one-pass kernels (~2 s of CPU). Both give the
#: same numbers (exact order statistics, the same sums).
ONE_PASS_MIN_TRIALS = 2**17

#: Largest |angular error| [rad] whose sine and cosine the compiled model takes from
#: their Taylor polynomials (sin to x^15, cos to x^16; :mod:`uq.physics.fusedkernels`) [1].
#: The first omitted terms relative to the result, x^16/17! = 6.5e-25 (sin x ~ x) and
#: x^18/18! = 1.1e-26 (cos x > 0.96) at 0.25 rad, are far below half an ulp (1.1e-16),
#: so the polynomials are as exact as libm. Larger errors use libm (14 deg covers INS
#: and geometry errors). [1] Abramowitz and Stegun (1964), 4.3.65-66.
SMALL_ANGLE = 0.25

#: Largest |a| for which the compiled model takes x^a of a power-law profile (a: the shear
#: exponent) from x0^a times the binomial series of (1 + d)^a, d = x / x0 - 1, |d| <= 1/129
#: (:func:`uq.physics.fusedkernels.power_near`). For |a| <= 1 the coefficients'
#: magnitudes do not grow after C(a, 1), so the remainder after the d^(K-1) term is at
#: most |C(a, K)| d^K / (1 - d) [1]; the kernel takes terms until that bound, over the
#: least the sum can be (1 - d), is below half an ulp (1.1e-16): 8 terms or fewer. Larger
#: exponents take libm's log and exp. [1] Abramowitz and Stegun (1964), 3.6.8.
POWER_SERIES_MAX_EXPONENT = 1.0

#: Trials per block of the compiled model (:func:`uq.fused.measurement_model`) [1]:
#: its scratch arrays (beams, gate heights; ~8 x 15 doubles per trial) stay in the L2
#: cache between the compiled loops and numpy's SIMD log and exp; the per-block Python
#: overhead (~20 us) stays below 2 % of a block's time.
FUSED_BLOCK_TRIALS = 2**12

#: Size of the strided sample that brackets an order statistic [1]
#: (:mod:`uq.engine.orderstats`): its sort costs ~20 us; the brackets it gives hold ~1 % of
#: the values around each wanted rank. [1] Floyd and Rivest (1975), sample selection.
ORDER_SAMPLE = 1024

# --- bounds on what an input may cost --------------------------------------------------

#: Largest configuration (scenario, golden, fit) file read [bytes]: the shipped ones are
#: 1-3 KiB; a larger file (or an endless stream such as /dev/zero) is refused unread.
MAX_CONFIG_BYTES = 1 << 20

#: Deepest nesting of a configuration file [levels]: a scenario has at most 5 (sweep ->
#: key -> mapping -> ...); PyYAML composes recursively, so depth bounds its stack.
MAX_CONFIG_DEPTH = 64

#: Most values a configuration file may expand to once YAML aliases are resolved [1]: the
#: shipped files hold a few hundred; an alias bomb ("billion laughs") holds 10^9.
MAX_CONFIG_NODES = 100_000

#: Largest magnitude of a number in a scenario [unit of its key]: the squares of every
#: quantity stay finite through the Monte Carlo moments (sums of 10^10 squares of 1e100 are
#: 1e210 < DBL_MAX = 1.8e308); no physical input comes near it.
MAX_MAGNITUDE = 1e100

#: Largest seed [1]: numpy's SeedSequence takes any integer, but the seed is recorded in
#: the results as a netCDF 64-bit unsigned attribute.
MAX_SEED = 2**64 - 1

#: Most scenes of a sweep (outer product) [1], and most values of one swept key; planned
#: before anything is allocated. 10^7 scenes of the GUM grid take ~2 min and ~8 GB of
#: results; larger grids are split by the user. Configurable: ``UQ_MAX_SCENES``.
MAX_SCENES = 10_000_000

#: Most combinations of swept structural keys (an error's size, the correction, the
#: gates: each a model of its own, validated and run separately, ~10 ms of fixed cost) [1].
MAX_GROUPS = 10_000

#: Most range gates and most beams of a lidar [1]: a conical scan has 50-100 lines of sight,
#: profilers 10-30 gates; each costs trials x beams x gates in the model.
MAX_GATES = 1000
MAX_BEAMS = 1000

#: Largest sampling.chunk_size [trials]: a chunk holds trials x inputs draws and the model's
#: temporaries; 2^24 trials of a 23-input scene are ~3 GB of draws.
MAX_CHUNK_SIZE = 2**22

# --- time-resolved motion --------------------------------------------------------------

#: Error bound of the dwell average per unit amplitude of the fastest motion component
#: [1] (:func:`uq.physics.timing.dwell_node_count`): 1e-9 of a 10 deg roll is 2e-10 rad,
#: ~2e-9 m/s of radial velocity at 10 m/s: far below any other error of the model.
DWELL_QUADRATURE_TOLERANCE = 1e-9

#: Most Gauss-Legendre nodes per panel of a dwell [1]: 32 nodes average a sinusoid over
#: up to ~71 of its radians (11 periods) to 1e-9 (:data:`uq.physics.timing.PANEL_SPAN`);
#: a conical scan's dwell of 20 ms needs 2-4. A longer dwell is cut into panels.
MAX_DWELL_NODES = 32

#: Most Gauss-Legendre nodes per dwell, over all its panels [1]
#: (:func:`uq.physics.timing.dwell_rule`): 16 panels of 32 nodes average a dwell of up to
#: ~1130 radians (180 periods) of the integrand's highest frequency to 1e-9. It bounds
#: memory: the numpy model holds (trials, beams, nodes, 3, 3) attitudes, 190 MB for a
#: slice of 2^10 trials of a 5-beam scan at 512 nodes. A lidar's dwell (0.02-2 s) of a
#: platform's motion (periods of 1 s and more) needs at most a few dozen.
MAX_DWELL_TOTAL_NODES = 512

#: Size [the output's unit: m s-1 or deg] under which a figure or a report takes a
#: deterministic number (an uncertainty, the correction's systematic error) for zero: far
#: above the rounding of the model's double arithmetic (values of ~10 m s-1 carry errors
#: of ~1e-15, ~1e-13 after a few dozen operations; a vanishing u comes out at ~1e-29) and
#: far below anything a lidar resolves (~1e-2 m s-1) or a report prints (4 digits of u).
NUMERICAL_ZERO = 1e-9

#: Shortest period of a platform motion [s] (harmonics, a spectrum's peak period; a
#: spectrum's band reaches at most 1 / this in Hz): an INS reports attitude and velocity at
#: up to 100-200 Hz, so a faster "motion" is vibration that no INS resolves and no
#: motion correction uses; and the phase w t of a faster one over a scan of minutes keeps
#: too few digits to mean anything (a period of 1e-300 s gave non-finite statistics with no
#: invalid trial counted).
MIN_MOTION_PERIOD = 0.01

#: Most components of a wave spectrum [1]: each is a Monte Carlo input (a random phase)
#: and a column of the GUM Jacobian; 256 resolve a JONSWAP peak (gamma 3.3, relative width
#: ~0.1) with ~20 bins across it over a band of 0.5-4 fp.
MAX_WAVE_COMPONENTS = 256

#: Largest motion record read [bytes]: a day of 10 Hz samples of six degrees of freedom is
#: ~50 MB of CSV; a longer record adds nothing a scan of seconds can use.
MAX_SERIES_BYTES = 64 << 20

#: Most rows of a motion record [1], counted before it is parsed: a day of 20 Hz samples
#: is 1.7 million; a longer record adds nothing a scan of seconds can use.
MAX_SERIES_ROWS = 2_000_000

#: Largest results file read whole by ``uq plot``, ``uq report`` and ``uq fit`` [bytes]:
#: it is loaded into memory; 10^4 scenes of the full model's outputs are ~100 MiB.
MAX_RESULTS_BYTES = 4 << 30

#: Largest fit table (``uq fit`` of a CSV) read [bytes]: its rows are bounded by
#: ``MAX_FIT_POINTS`` (10^4 rows of a few numbers, well under 1 MiB); the byte limit only
#: keeps the row count cheap to take.
MAX_FIT_TABLE_BYTES = 64 << 20

#: Largest table of 10-min records read by ``uq golden`` (CSV or netCDF) [bytes]: ten years
#: of records with a dozen columns at five heights are ~100 MiB of CSV.
MAX_RECORD_BYTES = 256 << 20

#: Most rows of a table of 10-min records [1], counted before it is parsed: 19 years.
MAX_RECORD_ROWS = 1_000_000

# --- probe volume ------------------------------------------------------------------------

#: Relative error allowed in a probe-weighted wind speed by the quadrature along the beam
#: [1] (:func:`uq.physics.probe.node_count`): 1e-6 of 10 m s-1 is 1e-5 m s-1, four orders
#: below a lidar's radial-velocity noise (~0.1 m s-1) and two below the smallest probe
#: bias of the typical configurations (~1e-4 relative, a pulsed lidar at 200 m).
PROBE_QUADRATURE_TOLERANCE = 1e-6

#: Most Gauss-Legendre nodes per beam and gate of a probe volume [1]. The typical
#: configurations need 10-20 (a pulsed lidar) and up to ~50 (a CW lidar whose truncated
#: tails reach the lens at 200-300 m from a lidar 2 m above the sea: the power law's branch
#: point at the sea surface then lies just beyond the end of the probe, which slows the
#: rule's convergence); a negative shear there needs ~100.
MAX_PROBE_NODES = 128

#: Nodes of the reference rule against which :func:`uq.physics.probe.node_count`
#: measures the error of every smaller rule [1]: twice MAX_PROBE_NODES, so that the
#: reference converges at twice the rate (in the number of nodes) of the largest rule
#: it judges; its own relative error is below 1e-12 in the hardest cases tested (a CW
#: probe focused 200-300 m out from 2-3 m above the sea).
PROBE_REFERENCE_NODES = 2 * MAX_PROBE_NODES

#: Two-sided Gaussian tail mass of the pulse beyond which the pulsed weighting is cut
#: for the quadrature [1]: the cut is numerical, not part of the model (its effect on a
#: weighted speed is below this mass times the relative spread of the speed, < 1e-10).
PULSE_TAIL_MASS = 1e-10

#: A typical pulsed lidar (WindCube-like) [m]: range-gate length 30 m (the "functional
#: probed length" of the WindCube user manual) and pulse FWHM 22.5 m (a 150 ns pulse,
#: Delta r = sqrt(ln 2) c sigma_p, Eq. 2.20), both as quoted by Matavar (2024), Sec. 2.2.3
#: (refs. [44], [86] there); OpenFAST's InflowWind lidar module also uses 30 m for the
#: WindCube.
WINDCUBE_GATE_LENGTH = 30.0
WINDCUBE_PULSE_FWHM = 22.5

#: A typical continuous-wave lidar (ZephIR-like) as modelled by OpenFAST's InflowWind
#: lidar module (modules/inflowwind/src/Lidar.f90: LsrWavLen = 1.565e-6 m, BeamRad =
#: 0.028 m, weighting truncated where it falls below 0.02 of its peak, WtFnTrunc):
#: wavelength [um], 1/e^2 beam radius at the lens [mm], truncation [1].
ZEPHIR_WAVELENGTH_UM = 1.565
ZEPHIR_BEAM_RADIUS_MM = 28.0
ZEPHIR_TRUNCATION = 0.02

# --- compiled time-resolved model (uq.physics.fusedmotion) -------------------------------

#: pi / 2 in three parts [rad] for the Cody-Waite argument reduction of the compiled
#: sine and cosine (:func:`uq.physics.fusedmotionkernels.sincos`): the first two carry
#: 33 significant bits each, so k times them is exact for |k| < 2^20, and their sum with
#: the third is pi / 2 to 1.01e-37 (tested). fdlibm's ``pio2_1``, ``pio2_2``, ``pio2_2t``
#: (Sun Microsystems, e_rem_pio2.c, 1993); Cody, W. J. and Waite, W. (1980). Software
#: Manual for the Elementary Functions. Prentice-Hall, Ch. 8.
HALF_PI_PARTS = (float.fromhex("0x1.921fb54400000p+0"), float.fromhex("0x1.0b4611a600000p-34"),
                 float.fromhex("0x1.3198a2e037073p-69"))

#: Largest |angle| [rad] whose sine and cosine the compiled time-resolved model takes
#: from its SIMD polynomials after reduction by k pi / 2 (beyond it, and for NaN, libm):
#: 2^19 pi / 2 keeps |k| <= 2^19, where k times the 33-bit parts of
#: :data:`HALF_PI_PARTS` is exact, so the reduced angle is exact to an ulp of itself
#: (fdlibm's medium-size path covers |x| < 2^20 pi / 2). The model's angles (attitudes,
#: w t of the motion) are below 1e4 rad.
SINCOS_REDUCTION_LIMIT = 2.0**19 * math.pi / 2

#: Largest sin^2 of the rotation between two INS samples [1] that the compiled slerp
#: (:func:`uq.physics.fusedmotionkernels.slerp_factors`) takes from its power series
#: (arcsin s / s to s^50; Abramowitz and Stegun (1964), 4.4.40): at sin^2 = 0.25 (30 deg
#: between samples) the first omitted term is 5e-19 relative. Larger rotations (an INS
#: slower than the motion) use libm.
SLERP_SERIES_LIMIT = 0.25

#: Doubles of scratch per block of trials in the compiled time-resolved model [1] (all
#: of a block's rows: the kernels' work rows, the platform states, beams, radial-velocity
#: parts, gate heights and least squares, :func:`uq.physics.fusedmotion.block_trials`):
#: 2^16 doubles = 512 kB, half the L2 cache of a core here (1 MB), so that the rows a
#: kernel's passes read again stay there; a point-wise DBS scan of one gate (~170
#: doubles per trial) then has blocks of 256 trials: 0.26 us per trial against 0.36 us
#: with the 2048 trials (1.4 MB of scratch) of a budget of node rows alone (measured on
#: the benchmark's point-wise scan, 2^18 trials, thread CPU time, 2026-11-25).
MOTION_BLOCK_VALUES = 2**16

#: Fewest and most trials per block of the compiled time-resolved model [1]: at least
#: 64 so that the per-block Python work (two kernel calls, numpy's log, exp and arctan2:
#: ~20 us) stays below ~1 % of a block's time for any scan; at most 2^11, beyond which a
#: larger block gains nothing (measured on a 5-beam DBS scan, scripts/bench_motion.py).
MOTION_BLOCK_TRIALS = (64, 2**11)

#: Values [-] by which each row of the compiled time-resolved model's block scratch is
#: longer than its trials (:func:`uq.physics.fusedmotion.block_scratch`): one 64-byte
#: line, so that rows of a power-of-two block (256 trials, 2 KiB) do not meet modulo the
#: 4 KiB a CPU's store-to-load check compares (4K aliasing; Intel 64 and IA-32
#: Optimization Reference Manual, Sec. 3.6.8.1). Measured on the 4-beam point-wise DBS of
#: uq.bench.targets.nacelle_models, 2^17 trials, CPU time: 0.030-0.034 s over processes
#: with rows of 256 values, 0.0297-0.0299 s with this pad (2026-11-25).
MOTION_BLOCK_ROW_PAD = 8

# --- Turbulence defaults -----------------------------------------------------------------
# IEC 61400-1 Ed. 3 (2005), Sec. 6.3 and Annex B: the turbulence scale parameter
# Lambda_1 = 0.7 z below 60 m above ground and 42 m above; the Mann (1994) uniform-shear
# model with L = 0.8 Lambda_1 and Gamma = 3.9 (Annex B.2); the Kaimal spectra with the
# longitudinal integral length L_u = 8.1 Lambda_1 (Table B.1).

#: Height above which the IEC turbulence scale parameter is constant [m]. IEC 61400-1
#: Ed. 3 (2005), Eq. 5.
IEC_SCALE_HEIGHT = 60.0
#: Turbulence scale parameter Lambda_1 above :data:`IEC_SCALE_HEIGHT` [m]. IEC 61400-1
#: Ed. 3 (2005), Eq. 5.
IEC_SCALE_PARAMETER = 42.0
#: Lambda_1 / z below :data:`IEC_SCALE_HEIGHT` [1]. IEC 61400-1 Ed. 3 (2005), Eq. 5.
IEC_SCALE_SLOPE = 0.7
#: Mann's length scale over Lambda_1 [1]: L = 0.8 Lambda_1 = 33.6 m above 60 m.
#: IEC 61400-1 Ed. 3 (2005), Annex B.2.
MANN_LENGTH_FACTOR = 0.8
#: Mann's shear anisotropy Gamma [1]. IEC 61400-1 Ed. 3 (2005), Annex B.2.
MANN_ANISOTROPY = 3.9
#: Kaimal's longitudinal integral length L_u over Lambda_1 [1]: L_u = 8.1 Lambda_1 =
#: 340.2 m above 60 m. IEC 61400-1 Ed. 3 (2005), Annex B, Table B.1.
KAIMAL_LENGTH_FACTOR = 8.1
#: Kaimal integral scales L_k of (u, v, w) over Lambda_1 [1] and standard deviations of
#: (u, v, w) over sigma_u [1]. IEC 61400-1 Ed. 3 (2005), Annex B, Table B.1.
IEC_KAIMAL_LENGTH_FACTORS = (KAIMAL_LENGTH_FACTOR, 2.7, 0.66)
IEC_KAIMAL_SIGMA_RATIOS = (1.0, 0.8, 0.5)
#: The exponential coherence exp(-a sqrt((f r / V)^2 + (b r / L_c)^2)): decrement a = 12
#: [1], b = 0.12 [1], L_c = 8.1 Lambda_1 (ratio [1]). IEC 61400-1 Ed. 3 (2005), Annex B,
#: Eq. B.13.
IEC_COHERENCE_DECREMENT = 12.0
IEC_COHERENCE_SCALE_RATIO = 0.12
IEC_COHERENCE_LENGTH_FACTOR = 8.1
#: Mann's length scale above 60 m [m]: 0.8 x 42 m = 33.6 m (IEC 61400-1 Ed. 3, Annex B).
MANN_LENGTH_SCALE_IEC = MANN_LENGTH_FACTOR * IEC_SCALE_PARAMETER
#: Largest turbulence intensity a scenario accepts [1]: sigma_u / U beyond 0.5 breaks
#: Taylor's frozen-turbulence hypothesis (it needs sigma_u << U; Willis and Deardorff
#: 1976, J. Atmos. Sci. 33, 1530, find it holds to sigma_u / U ~ 0.5) that both paths use.
MAX_TURBULENCE_INTENSITY = 0.5
#: Smallest turbulence intensity a scenario accepts [1]: sigma_u = 1e-6 U is 1e-5 m s-1 at
#: 10 m s-1, three orders below any lidar's radial-velocity resolution (~1 cm s-1); far
#: below it the records' variances (~(I U)^2) underflow float64 (a TI of 1e-300 has a
#: variance of 1e-598 m2 s-2, which is 0) and their ratios are 0 / 0.
MIN_TURBULENCE_INTENSITY = 1e-6
#: Longest length scale a scenario accepts [m]: 10 km, beyond any atmospheric surface
#: layer's integral length (the Kaimal L_u of IEC 61400-1 is 340 m).
MAX_LENGTH_SCALE = 10_000.0
#: Largest Mann anisotropy accepted [1]: fits to atmospheric data give 0-5 (Mann 1994,
#: J. Fluid Mech. 273, 141; Peña et al. 2010, BLM 137, 173); 10 leaves a margin.
MAX_ANISOTROPY = 10.0
#: Longest record [s]: one hour (IEC 61400-12-1 uses 10-min records; longer ones are
#: non-stationary and outside the frozen, homogeneous field of the model).
MAX_RECORD_DURATION = 3600.0
#: Most scans in one record [1]: a bound on the cost of a record before anything is
#: allocated (2^20 scans of a 5-beam DBS is 5 x 2^20 lines of sight: 40 MB per gate and
#: probe node in float64); a 600-s record of 1-ms beams of a 5-beam DBS has 120 000.
MAX_RECORD_SCANS = 2**20
#: Standard deviations of a random-phase motion's displacement taken for its reach in a
#: record at validation [1] (uq.pipeline.turbulencesection.motion_reach: the box a record
#: needs is counted before any record is drawn): a sum of many harmonics is near
#: Gaussian, and over a ten-minute record of a 7-s sea (~90 cycles) its largest value is
#: ~sqrt(2 ln 90) = 3.0 sigma (floating_lidar_ti's records reach 1.8-2.0 sigma). A record
#: that reaches further and needs a box above the limit is refused in one line when its
#: box is counted, before anything is allocated.
MOTION_REACH_SIGMAS = 3.0
#: Default Monte Carlo records per scene (``record.count``) [1]: each record costs a
#: turbulence box (~7 s CPU for a 600-s record of a 5-beam DBS at 10 m s-1, L = 33.6 m, on
#: one core here); with 20 records the standard error of the mean apparent TI is its
#: spread over the records / sqrt(20) = 0.22 of that spread.
DEFAULT_RECORDS = 20
#: Most records per scene (``record.count``) [1]: a bound on the run's cost (boxes).
MAX_RECORDS = 10_000
#: Gauss-Legendre nodes along the beam with which a probe's weighting samples the
#: turbulent field [1]: the quadrature of the weighting's transfer function
#: integral W(s) exp(i k s) ds with 48 nodes is within 1e-3 of the exact one for
#: k h <= 70 (h the rule's half length: k <= 0.9 rad m-1 for a pulsed gate of 18.75 m and
#: pulse of 24.75 m, h = 77 m, beyond the Nyquist wavenumber pi / (L / 8) = 0.75 rad m-1
#: of a box of the IEC L = 33.6 m; 32 nodes reach only k h = 39, 0.5 rad m-1, and their
#: response between 0.5 and 0.75 rad m-1 aliases up to 0.5); for a CW Lorentzian cut at
#: 2 % (h = 7 z_R) the "tan" rule holds for k h <= 50. Beyond its reach a rule aliases:
#: a field sampled with it must carry no wavenumbers above that. Measured against the
#: closed forms in tests/pipeline/test_turbulencesection.py.
TURBULENCE_PROBE_NODES = 48
#: k h up to which the :data:`TURBULENCE_PROBE_NODES`-node rule holds to 1e-3 [1],
#: per probe kind (measured, see above).
TURBULENCE_PROBE_REACH = {"pulsed": 70.0, "cw": 50.0}
#: A CW lidar's weighting in the records (uq.pipeline.turbulencesection.probe_quadrature):
#: the Lorentzian cut at the lens (s >= -F, no beam behind it) as the spectral path
#: takes it, read up to CW_RECORD_FAR_CUT focus distances beyond the focus (the field is
#: not read farther: that tail's weight, 2 z_R / (3 pi F) of the mass, is dropped, not
#: spread over the rest), on a "tan" rule of CW_RECORD_PROBE_NODES nodes. Measured with
#: the spectral path (its ratios with this rule's own transfer against the uncut one,
#: tests/pipeline/test_turbulencesection.py): a CW VAD's u, v, w variance ratios at 40-100
#: m move by < 0.3 % (their TIs by < 0.15 %), where a cut at the focus distance (s <= F)
#: moved them by up to 1.1 % and the per-scan truncation of 2 % by 4-9 %.
CW_RECORD_FAR_CUT = 2.0
CW_RECORD_PROBE_NODES = 96
# --- Turbulence -----------------------------------------------------------------------

#: Von Karman energy spectrum's exponent 17/6 [1], also the second parameter of Mann's
#: eddy lifetime 2F1(1/3, 17/6; 4/3; -(kL)^-2): Mann (1994), Sec. 3 (a property of the
#: spectrum, E ~ k^4 at small k and k^(-5/3) at large k, not a tunable).
VON_KARMAN_EXPONENT = 17.0 / 6.0

#: Nodes per decade of the tabulated eddy lifetime (log-linear interpolation of
#: beta(kL) between nodes; the interpolation's relative error is 3.4e-6 at 200 per
#: decade, tested below 1e-5) and the kL range of the table [1]; outside it the exact asymptotes
#: (kL)^-1 and (kL)^-2/3 hold to < 1e-8 (tested).
EDDY_LIFETIME_TABLE_PER_DECADE = 200
EDDY_LIFETIME_TABLE_RANGE = (1e-4, 1e4)

#: Most cells of a generated turbulence box [1]: the FFT generator holds the three
#: components in float64 plus their half spectra (~ 3 x 8 + 3 x 8 + a 9-entry factor of
#: one slab) bytes per cell, ~1 GB at 2^24 cells, the memory a 2-core machine shared
#: with others can give one record. Boxes above it are refused (box_for, mann_box).
MAX_BOX_CELLS = 2**24
#: Most cells of a record's box [1] (uq.pipeline.records.record_grid, checked at
#: validation): its half spectra are held in parts of at most RECORD_SPECTRA_BYTES and
#: only the probes' (y, z) lines come back from the transforms, so its memory does not
#: grow with its cells; its time does (~2 x a box of MAX_BOX_CELLS). A CW VAD's box,
#: which reaches from the lens to three focus distances, needs ~2.8e7 at 100 m.
RECORD_MAX_BOX_CELLS = 2**25

#: Cells of one slab of the spectral factor computed at a time [1]: nine float64 arrays
#: of that size (2^20: 72 MB) bound the factor's memory whatever the box.
BOX_SLAB_CELLS = 2**20

#: Margin around the probe points of a periodic (Mann) box in each of y and z, in units
#: of the length scale L on each side [1]: the box is then >= 6 L wide, and the variance
#: its discrete wavenumbers keep is reported by turbulencebox.box_variance (tested).
BOX_MARGIN_LENGTH_SCALES = 3.0

#: Default cells per length scale of a box's spacing [1] (box_for: spacing L / 8, 4.2 m
#: at IEC's L = 33.6 m): a pulsed lidar's probe (~25-30 m) spans 6-7 cells; the variance
#: the box's resolution keeps is what box_variance reports (tested).
BOX_DEFAULT_CELLS_PER_LENGTH = 8.0

#: Probe-quadrature points sampled at a time in a record (turbulencesampling) [1]: each
#: point holds ~ 8 corners x 3 components of float64 temporaries, so 2^18 points keep a
#: chunk's memory near 50 MB; records do not depend on it.
SAMPLING_CHUNK_POINTS = 2**18

#: Bytes of unit-field records a run keeps for reuse (uq.pipeline.records.unit_record)
#: [1]: a record's turbulence along the beams for a field of unit scale, reused by every
#: scene that draws the same record from the same box (a sweep of turbulence.intensity
#: or of the correction); a record of a 50-beam VAD over 10 min at 4 gates is ~1 MB,
#: so 64 MB keeps every record of any shipped scenario. Results do not depend on it.
UNIT_RECORD_CACHE_BYTES = 2**26
#: Spectral paths of record mode kept per process for a run's other chunks [1]
#: (:func:`uq.pipeline.records.scene_spectral_paths`): a few numbers per gate each;
#: 64 covers every shipped sweep's distinct lidars. Results do not depend on it.
SPECTRAL_PATHS_KEPT = 64
#: Cells of a record's box transformed, or of its factor's variance summed, at a time
#: [1]: 2^18 keeps each slab's temporaries near 4 MB (the box's half spectra, ~24 bytes
#: a cell, are the record's memory); boxes do not depend on it.
RECORD_BOX_SLAB_CELLS = 2**18
#: Most bytes of a record box's half spectra held at a time [1] (records.unit_box): a
#: ten-minute box at L / 8 (~1500 x 96 x 96 cells) has ~340 MB of them, which a run's
#: ~300 MB of code and libraries would take above 600 MB; in parts of at most 256 MB
#: (two for the shipped scenarios) it stays below, at the cost of drawing the noise and
#: taking its 2-D transforms once more per part (~0.8 s a box). Boxes do not depend on it.
RECORD_SPECTRA_BYTES = 2**28
#: Threads of scipy's FFTs of a record's box [1] (records.unit_box_parts): they share out
#: independent 1-D transforms, so the box is the same bits on any number; 2 halve the
#: transforms' wall time on an idle 2-core machine (the x transforms of a ten-minute box
#: 0.19 -> 0.10 s), where a record-mode run's first run is measured.
RECORD_FFT_WORKERS = 2

#: Usable CPUs from which a first run's background compile runs beside the run
#: (uq.cli.firstrun.compile_beside) [1]: a run's numpy chunks take up to 4 threads
#: (uq.pipeline.runner.NUMPY_CHUNK_THREADS), so from the fifth a core is left to the
#: compile; with fewer it waits for the run to end (beside it, it slowed the run by
#: 20-30 % on 2 cores and ended after it).
BACKGROUND_BESIDE_MIN_CPUS = 5
#: Estimated CPU time of a run's model [s] (uq.pipeline.estimate.RunSize.model_seconds:
#: its trials and scenes, not its start or records) from which the background compile
#: runs beside the run on any number of CPUs (uq.cli.firstrun.compile_beside): a long
#: first run then takes the compiled model once it is cached, instead of the numpy model
#: throughout. Measured on an idle 2-core machine, `uq run rubio2022_misalignment` with
#: an empty cache, waiting for the run to end against beside it: sampling.n = 50,000
#: (estimated 26 s) 29.4 against 32.7 s (19.1 s warm); 75,000 (39 s) 41.9 against
#: 35.9 s (18.9 s warm); 120,000 (62 s) 61.2 against 41.5 s (25.8 s warm); 200,000
#: (104 s) 98.8 against 43.0 s (27.7 s warm): the two cross near 30 s. The shipped
#: files' models are estimated at 9 s at most.
BACKGROUND_BESIDE_MIN_MODEL_CPU_S = 30.0

#: Cell averaging of the Mann tensor near the k1 axis (turbulencebox.cell_averaged_factors)
#: [1]: cells with |k1| <= CELL_AVERAGE_K1 max(dk2, dk3), beyond which the tensor varies
#: across a cell on scales >= the cell (point values suffice; the variance's change from
#: doubling it is tested); Gauss nodes along k1; the graded rule's panel ratio and number
#: of panels per side (down to 4^-6 = 1/4096 of a half cell, below dk1 / dk2 of any box
#: within the cell limit's aspect ratios).
CELL_AVERAGE_K1 = 4.0
CELL_AVERAGE_K1_NODES = 3
CELL_AVERAGE_GRADING = (0.25, 6)

# --- Turbulence spectra -------------------------------------------------------------------

#: Quadrature of the spectral path (:class:`uq.physics.spectraltensor.WavenumberGrid`),
#: tested for convergence in tests/physics/test_spectraltensor.py: k1 L from 1e-6 to 1e6
#: and the polar radius rho / sqrt(k1^2 + L^-2) from 1e-5 to 1e4 (the sheared tensor keeps
#: energy at rho << k1 for small k: 8e-4 of sigma_u^2 lies below 1e-3; the inertial tail
#: beyond 1e6 holds (1e6)^(-2/3) = 1e-4); Gauss-Legendre nodes per decade of k1 and of
#: rho; trapezoid nodes in the polar angle (periodic: spectral convergence).
SPECTRAL_K_DECADES = (-6.0, 6.0)
SPECTRAL_K1_PER_DECADE = 12
SPECTRAL_RADIUS_DECADES = (-5.0, 4.0)
SPECTRAL_RADIUS_PER_DECADE = 8
SPECTRAL_ANGLE_NODES = 48
#: Frequencies of the Kaimal path: f L_u / U from 1e-5 to 1e5 [1].
KAIMAL_FREQUENCY_DECADES = (-5.0, 5.0)
#: Largest estimated relative error of a spectral ratio (u, v, w) that the spectral path
#: accepts before it refines its rules [1] (uq.physics.lidarspectral). The estimate is
#: the difference from a coarser rule (two nodes fewer a panel; for a VAD's log-polar
#: grid 2/3 of its k1 nodes and 3/4 of the others), which overstates the error 3-5 times
#: (measured: a pulsed DBS at 40-300 m and a CW VAD at 40-100 m move by < 1.5e-3 when
#: their rules are refined, where the estimates say 2e-3 to 6e-3).
SPECTRAL_TOLERANCE = 1e-2
#: Most refinements of the spectral path's rules before it reports a result as not
#: converged [1] (each costs ~2.4 times the one before).
SPECTRAL_REFINEMENTS = 2

#: Golden TI: a record is 10 min [s] (IEC 61400-12-1); the
#: representative TI is the mean plus 1.28 standard deviations (IEC 61400-1:2005 Sec.
#: 6.3.1: the 90 % quantile of a normal distribution of the 10-min TI).
GOLDEN_RECORD_SECONDS = 600.0
REPRESENTATIVE_TI_QUANTILE = 1.28
#: Most (y, z) points of a Kaimal box [1] (turbulencebox.kaimal_box): Veers' method
#: factors a points x points coherence matrix per wavenumber (~P^3 / 3 flops each), so
#: 1024 points and the ~750 wavenumbers of a ten-minute record cost ~3e11 flops, about a
#: minute on two cores; a 5-beam DBS at 100 m at the default spacing needs ~720.
MAX_KAIMAL_POINTS = 1024

#: Campaign records (uq campaign). Lowest mean speed of a record the correction takes
#: [m s-1]: below it the ten-minute record is no frozen field advected past the lidar
#: (Taylor's hypothesis needs sigma_u << U; at 2 m/s a TI of 0.25 is sigma_u = 0.5 m/s)
#: and ``Vh = |u_h|`` is no longer linear in the fluctuations; IEC 61400-12-1's power
#: curves and the OWA roadmap's TI bins start above it. Configurable
#: (``campaign.minimum_speed``).
CAMPAIGN_MIN_SPEED = 2.0
#: A record is 10 min (the campaign's grid of records) [s].
CAMPAIGN_RECORD_SECONDS = 600.0
#: Records of one chunk of the correction (the fast path's arrays: ~50 MB at 24 motion
#: components; a dask task each).
CAMPAIGN_CHUNK_RECORDS = 4096
#: Most threads ``uq campaign`` runs its tables' nodes and records' chunks on without a
#: dask client [1] (one per CPU the process may use, up to this).
CAMPAIGN_THREADS = 8

#: The per-axis rule of the unresolved scales' integral (:mod:`uq.physics.unresolved`):
#: Gauss-Legendre panels per decade outside the box's Nyquist cube and inside it, down
#: to the fraction of the Nyquist wavenumber given (below it the integrand vanishes as
#: (k d)^2: the interpolation and the probe's quadrature pass those scales whole) [1].
#: One refinement (twice the panels) moves the beams' unresolved variance by under
#: 1 % of itself on the shipped record scenarios (tests/physics/test_unresolved.py).
UNRESOLVED_PANELS = (4, 1e-2)
#: Gauss-Legendre nodes per panel of that rule [1].
UNRESOLVED_ORDER = 4
#: Reach of that rule, in Nyquist wavenumbers pi / d: beyond it the tensor's k^(-11/3)
#: leaves (1 / reach)^(2/3) = 1 % of the outer shell's variance [1].
UNRESOLVED_REACH = 1000.0
#: Nodes of the table of the probe quadrature's power up to the cube's corner [1].
UNRESOLVED_QUADRATURE_TABLE = 8193
#: How near 1 a record run's ``turbulence_intensity_box_kept`` is read as "every band of
#: the field drawn" (the box, the scales below its cells and the band larger than it add
#: up to the field's record covariance to rounding, ~1e-12) [1]; a file whose records
#: left out the band larger than the box reads below it by 0.3-2 %.
BOX_KEPT_WHOLE = 1e-6
