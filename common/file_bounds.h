/* file_bounds: the physical bounds of what a run file holds (docs/format.md, "Physical
 * bounds"), and the share of them a model's parameters may take. The writer and the reader
 * check every value against CDEM_FILE_MAX_* (common/h5/h5_layout.c); the parameter checks
 * (common/params.c, solver/run/run_validate.c) refuse a model that would leave them, from
 * the same numbers, so that `cdem-run --summary` refuses every model whose file the writer
 * would refuse (docs/reliability.md, "Round four", row 2). No state; constants only. */
#ifndef CDEM_FILE_BOUNDS_H
#define CDEM_FILE_BOUNDS_H

/* A checksum only says the bytes are those written; these say the values are a model's. The
 * reader refuses a value outside them as damage, naming the file, dataset, row and value; the
 * writer refuses to write one (CDEM_ERR_NUMERIC: a run that produced it has blown up), so a
 * file cdem-c writes is always one it reads. They keep every square and sum over all elements
 * finite. */
#define CDEM_FILE_MAX_LENGTH 1e7  /* m: |x|, |y|, |net displacement|, |sea level| */
#define CDEM_FILE_MAX_RADIUS 1e5  /* m: radius in (0, this] */
#define CDEM_FILE_MAX_TIME   1e9  /* s: model time in [0, this] */
#define CDEM_FILE_MAX_STRESS 1e20 /* N/m: |sxx|, |syy|, |sxy|, |differential stress| */
#define CDEM_FILE_MAX_STRAIN 1e6  /* |axial strain|: the length bound over a 10 m sample */

/* The largest element radius of a model, in model units, before radius_scale (the fourth of
 * the paper's radii 0.05, 0.075, 0.1, 0.125; solver/base/model.c). */
#define CDEM_LARGEST_RADIUS_UNITS 0.125

/* What the parameters alone may ask of the length bound: the box itself (width, and height x
 * wall_height_multiplier, times unit_scaling) within it. cdem-run's extent rule
 * (solver/run/run_validate.c) adds what only the model knows: the mode's base beyond the
 * walls (repose), the boundaries' displacement over the run and a largest radius. */
#define CDEM_MODEL_MAX_SIZE CDEM_FILE_MAX_LENGTH

#endif
