/* Tests of solver/run/summary.c: the key lines of the model summary for the default model and
 * for every boundary mode, with numbers checked against the model (not hard-coded output). */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include "bc.h"
#include "estimate.h"
#include "h5format.h"
#include "model.h"
#include "params.h"
#include "summary.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char *summary_of(const cdem_params *p, long n, long nw, int estimated) {
    cdem_model m;
    cdem_error err;
    cdem_error_clear(&err);
    assert_int_equal(cdem_bc_derive_model(p, &m, &err), CDEM_OK);
    char *text = NULL;
    assert_int_equal(cdem_summary_text(p, &m, n, nw, estimated, &text, &err), CDEM_OK);
    assert_non_null(text);
    return text;
}

/* Finds "label:" and checks that the rest of its line starts (after padding) with value. */
static void assert_line(const char *text, const char *label, const char *value) {
    char key[128];
    snprintf(key, sizeof key, "  %s:", label);
    const char *at = strstr(text, key);
    if (!at) {
        print_error("summary has no line \"%s\":\n%s\n", label, text);
        fail();
    }
    at += strlen(key);
    while (*at == ' ')
        at++;
    if (strncmp(at, value, strlen(value)) != 0) {
        const char *eol = strchr(at, '\n');
        print_error("line \"%s\" is \"%.*s\", expected \"%s...\"\n", label,
                    (int)(eol ? eol - at : 60), at, value);
        fail();
    }
}

static void test_summary_default_model_key_lines(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    char *t = summary_of(&p, 2121, 200, 0);
    assert_line(t, "elements", "2321 in increment 0");
    assert_line(t, "free elements", "2121\n");
    assert_line(t, "wall and fault elements", "200\n");
    assert_line(t, "assembly", "10 x 5 units = 10000 x 5000 m");
    assert_line(t, "radius 1", "50 m, mass 1.9635e+07 kg/m");
    assert_line(t, "radius 4", "125 m, mass 1.22718e+08 kg/m");
    assert_line(t, "normal stiffness Kn", "1544871985 N/m");
    assert_line(t, "shear stiffness Ks", "1544871985 N/m");
    assert_line(t, "damping", "84553183 N s/m");
    assert_line(t, "time step dt", "0.0281844 s");
    assert_line(t, "gravity", "9.81 m/s^2");
    assert_line(t, "density", "2500 kg/m^3");
    assert_line(t, "equilibration", "400 s = 14192 time steps");
    assert_line(t, "runtime", "2000 s = 70961 time steps");
    assert_line(t, "boundary speed", "0.70461 m/s");
    assert_line(t, "total displacement", "1127.38 m");
    assert_line(t, "increments", "283, numbered 0..282\n");
    assert_line(t, "end of equilibration", "increment 56\n");
    assert_line(t, "mode", "planar-fault");
    assert_line(t, "fault dip", "30 degrees");
    assert_line(t, "fault location", "0.5 of the base = 5000 m");
    assert_line(t, "element-element", "friction 0.25, cohesion 5e+09 N");
    assert_line(t, "element-wall", "friction 0.25, cohesion 5e+09 N");
    assert_line(t, "element-fault", "friction 0.25, cohesion 5e+09 N");
    assert_line(t, "sedimentation", "off");
    assert_null(strstr(t, "estimated"));
    /* deterministic: the same parameters give the same text */
    char *again = summary_of(&p, 2121, 200, 0);
    assert_string_equal(t, again);
    free(again);
    free(t);
}

static void test_summary_estimated_counts_say_so(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    char *t = summary_of(&p, 2121, 200, 1);
    assert_line(t, "elements", "2321 in increment 0 (estimated");
    assert_line(t, "free elements", "2121 (estimated)");
    assert_line(t, "wall and fault elements", "200 (estimated)");
    free(t);
}

static void test_summary_modes_geometry(void **state) {
    (void)state;
    static const struct {
        const char *overrides[5];
        const char *label, *value;
    } cases[] = {
        {{"boundary.mode=listric-fault", "boundary.kinematics=cd", NULL},
         "kinematics",
         "constant displacement (CD, mylar sheet)"},
        {{"boundary.mode=listric-fault", NULL},
         "fault dip",
         "30 degrees at the base, steepening to 90 degrees"},
        {{"boundary.mode=irregular-fault", "boundary.fault_file=f.txt", NULL},
         "fault vertices",
         "f.txt"},
        {{"boundary.mode=vertical-faults", "boundary.vertical_sense=piston", NULL},
         "sense",
         "piston"},
        {{"boundary.mode=vertical-faults", NULL}, "second fault", "0.65 of the base = 6500 m"},
        {{"boundary.mode=vertical-faults", NULL}, "block width", "3000 m"},
        {{"boundary.mode=detachment", "boundary.detachment_walls=both", NULL},
         "moving walls",
         "both walls"},
        {{"boundary.mode=repose", "boundary.repose_walls=both", NULL},
         "walls removed",
         "both walls"},
        {{"boundary.mode=repose", NULL}, "display interval", "5 s ="},
        {{"boundary.mode=repose", NULL},
         "base",
         "extends 10000 m (the assembly's width) beyond "
         "the removed wall"},
        {{"boundary.mode=repose", "boundary.repose_walls=both", NULL},
         "base",
         "extends 10000 m (the assembly's width) beyond each removed wall"},
        {{"boundary.mode=biaxial", "boundary.confining_pressure=2e7", NULL},
         "confining pressure",
         "2e+07 N/m (20 MPa in 3-D), ramped from zero at 200 s to full at 400 s"},
        {{"boundary.mode=biaxial", NULL}, "gravity", "0 m/s^2 (off in the biaxial test)"},
        {{"boundary.inversion=on", "boundary.inversion_percent=75", NULL},
         "net displacement",
         "563.7 m normal"},
        {{"boundary.inversion=on", NULL}, "net displacement", "0 m"},
        /* settling steps move nothing: 7 deposits x 2838 steps come off the reverse slip */
        {{"boundary.inversion=on", "surface.sedimentation=on", NULL},
         "inversion",
         "at 50 % of the deformation steps: 563.7 m normal, then 169.2 m reverse (7 deposits "
         "settle, 2838 steps each, with the boundaries still)"},
        {{"boundary.inversion=on", "surface.sedimentation=on", NULL},
         "net displacement",
         "394.5 m normal"},
        {{"material.material=bonded", "material.wall_breaking_strain=0.05", NULL},
         "element-wall",
         "breaking strain 0.05"},
        {{"material.first_slip=off", NULL}, "cohesion lost", "when the pair separates"},
        {{"heterogeneity.weak_interval=lower", "heterogeneity.weak_density_percent=80", NULL},
         "interval density",
         "80 % = 2000 kg/m^3"},
        {{"heterogeneity.weak_interval=upper", "heterogeneity.weak_thickness_percent=20", NULL},
         "weak/light interval",
         "upper 20 % of the height = 1000 m"},
        {{"heterogeneity.layered_friction=on", NULL},
         "layered friction",
         "layers 5-8, 13-16, 21-24 friction 0.1"},
        {{"surface.overburden_pressure=5e6", NULL}, "overburden pressure", "5e+06 N/m"},
        {{"surface.erosion=on", "surface.erosion_base_level=1.5", NULL},
         "erosion",
         "above 1.5 x the assembly height = 7500 m"},
        {{"surface.sedimentation=on", "surface.sea_level_rise=mid", NULL},
         "sea-level rise",
         "mid (factor 0.5"},
        {{"surface.sedimentation=on", NULL},
         "sediment interval",
         "150 m of boundary displacement = 7553 time steps"},
        {{"surface.sedimentation=on", NULL}, "settling time", "80 s = 2838 time steps"},
        {{"assembly.unit_scaling=200", NULL},
         "normal stiffness Kn",
         "349022201.5 N/m (scaled with the average radius)"},
    };
    for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        cdem_params p;
        cdem_error err;
        cdem_params_defaults(&p);
        for (size_t j = 0; cases[i].overrides[j]; j++)
            assert_int_equal(cdem_params_override(&p, cases[i].overrides[j], &err), CDEM_OK);
        char *t = summary_of(&p, 100, 10, 0);
        assert_line(t, cases[i].label, cases[i].value);
        free(t);
    }
}

static void test_summary_rejects_null(void **state) {
    (void)state;
    cdem_params p;
    cdem_model m;
    cdem_error err;
    cdem_params_defaults(&p);
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    char *t = (char *)&p;
    assert_int_equal(cdem_summary_text(NULL, &m, 1, 1, 0, &t, &err), CDEM_ERR_INVALID);
    assert_null(t);
    assert_int_equal(cdem_summary_text(&p, &m, 1, 1, 0, NULL, &err), CDEM_ERR_INVALID);
}

/* The salt's section (docs/solver.md, section 9.4): the time mapping and the ratio it keeps.
 * The default model with basal salt: dt 0.0264393 s (the salt's smallest mass), boundary
 * speed 0.660983 m/s, 1 mm/yr: S = 0.660983 / 3.16881e-11 = 2.086e10, 10^18 / S =
 * 4.794e7 Pa s; without salt no section. */
static void test_summary_salt_time_mapping(void **state) {
    (void)state;
    cdem_params p;
    cdem_params_defaults(&p);
    char *t = summary_of(&p, 2121, 200, 0);
    assert_null(strstr(t, "\nSalt\n"));
    free(t);
    p.salt_layer = CDEM_SALT_BASAL;
    p.damping_mode = CDEM_DAMPING_CONTACT;
    p.mode = CDEM_MODE_DETACHMENT;
    t = summary_of(&p, 2121, 200, 0);
    assert_non_null(strstr(t, "\nSalt\n"));
    assert_line(t, "time step dt", "0.0264393 s");
    assert_line(t, "smallest mass", "1.72788e+07 kg/m (salt)");
    assert_line(t, "layer", "basal, lowest 25 % of the span of element centres = 1250 m");
    assert_line(t, "viscosity", "1e+18 Pa s geological = 4.794e+07 Pa s in the model");
    assert_line(t, "geological rate", "1 mm/yr = 3.169e-11 m/s, shown by the model's 0.660983");
    assert_line(t, "time scale S", "2.086e+10 (1 model s = 661 yr");
    assert_line(t, "deformation phase", "1600 s of model time = 1.058 Myr");
    assert_line(t, "eta V / (rho g h H)", "0.000276 (salt 1250 m, cover 3750 m)");
    assert_line(t, "Reynolds number", "0.0379");
    assert_line(t, "damping", "79317916 N s/m in equilibration and settling; contact dashpots");
    free(t);
    /* ten times slower in nature: S ten times larger, the model's viscosity ten times smaller,
     * and the ratio eta V / (rho g h H) ten times smaller in the model as in nature (the model
     * keeps nature's ratio, whatever it is) */
    p.salt_rate = 0.1;
    t = summary_of(&p, 2121, 200, 0);
    assert_line(t, "viscosity", "1e+18 Pa s geological = 4.794e+06 Pa s in the model");
    assert_line(t, "time scale S", "2.086e+11");
    assert_line(t, "eta V / (rho g h H)", "2.76e-05");
    assert_line(t, "deformation phase", "1600 s of model time = 10.58 Myr");
    free(t);
}

/* Issue 46, item 8: the summary of a large model says, before any run, what it will cost:
 * the wall time from the documented per-element cost (labelled with its CPU), the output
 * file's size from the format's measured bytes per element, and the slip the runtime gives.
 * cdem2D's finer assemblies (radius_scale 0.1: about 212,000 elements, 709,613 time steps; no
 * run, no packing: the counts are given). */
static void test_summary_large_model_estimates(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    assert_int_equal(cdem_params_override(&p, "assembly.radius_scale=0.1", &err), CDEM_OK);
    cdem_model m;
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    assert_int_equal(m.total_steps, 709613);
    const long n = 210000, nw = 2000;
    char *t = summary_of(&p, n, nw, 0);
    assert_line(t, "element-steps", "1.5e+11 (212000 elements x 709613 time steps)");
    /* 30 increments (5 m of slip each); 212,000 x 709,613 x 15 ns + 212,000 x 30 x 1 us =
     * 2256.6 + 6.4 s = 37.7 min; 0.6 of it on two threads */
    assert_int_equal(m.n_increments_total + 1, 30);
    const double wall = cdem_estimate_wall_seconds((double)(n + nw), 709613.0, 30.0);
    assert_true(wall > 2260.0 && wall < 2265.0);
    assert_line(t, "wall time",
                "about 37.7 min on one thread and 22.6 min on two of an AMD EPYC "
                "(Zen 5) at 15 ns per element-step");
    /* the output file: 65,536 + 30 (512 + 212,000 x 13.5) bytes = 85.9 MB */
    char want[128];
    snprintf(want, sizeof want, "about %.3g MB (30 increments of 212000 elements)",
             cdem_h5_estimate_file_size(212000.0, 30.0, 0) / 1e6);
    assert_line(t, "output file", want);
    assert_line(t, "output file",
                "about 85.9 MB (30 increments of 212000 elements); 256 MB with "
                "the checkpoint slots");
    assert_line(t, "memory", "about 267 MB (1100 bytes per element)");
    /* the slip the runtime gives: a tenth of the default's 1127.38 m (dt is a tenth) */
    snprintf(want, sizeof want, "%.6g m in the 1600 s after equilibration", m.total_displacement);
    assert_line(t, "slip over the runtime", want);
    assert_line(t, "slip over the runtime", "112.738 m in the 1600 s after equilibration");
    free(t);
}

/* Issue 46, item 8: the equilibration rule of thumb (estimate.h) warns, before the run, for
 * an assembly too tall to settle in cdem's default 400 s (examples/inversion's 128 average
 * diameters: it settled in about 2500 s, measured), and not for the default model (29
 * diameters, at rest after about 200 s) nor for the inversion's own 3000 s. */
static void test_summary_equilibration_warning(void **state) {
    (void)state;
    cdem_params p;
    cdem_error err;
    cdem_params_defaults(&p);
    char *t = summary_of(&p, 2121, 200, 0);
    assert_line(t, "equilibration needed", "about 300 s for an assembly 29 average diameters");
    assert_null(strstr(t, "  warning:"));
    free(t);

    assert_int_equal(cdem_params_override(&p, "assembly.unit_scaling=125", &err), CDEM_OK);
    assert_int_equal(cdem_params_override(&p, "assembly.height=22.4", &err), CDEM_OK);
    assert_int_equal(cdem_params_override(&p, "assembly.width=50", &err), CDEM_OK);
    t = summary_of(&p, 47000, 900, 0);
    assert_line(t, "equilibration needed", "about 2800 s for an assembly 128 average diameters");
    assert_line(t, "warning",
                "time.equilibration = 400 s is shorter: the assembly will still "
                "be settling when the boundaries start to move; use "
                "time.equilibration = 2800 or more");
    free(t);
    assert_int_equal(cdem_params_override(&p, "time.equilibration=3000", &err), CDEM_OK);
    assert_int_equal(cdem_params_override(&p, "time.runtime=15000", &err), CDEM_OK);
    t = summary_of(&p, 47000, 900, 0);
    assert_null(strstr(t, "  warning:"));
    free(t);

    /* the rule: taller (in diameters) needs longer; no gravity, nothing to settle */
    cdem_model m;
    cdem_params_defaults(&p);
    assert_int_equal(cdem_bc_derive_model(&p, &m, &err), CDEM_OK);
    const double base = cdem_estimate_equilibration_needed(&m);
    m.height_m *= 2.0;
    assert_true(cdem_estimate_equilibration_needed(&m) > base);
    m.gravity = 0.0;
    assert_true(cdem_estimate_equilibration_needed(&m) == 0.0);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_summary_default_model_key_lines),
        cmocka_unit_test(test_summary_estimated_counts_say_so),
        cmocka_unit_test(test_summary_modes_geometry),
        cmocka_unit_test(test_summary_rejects_null),
        cmocka_unit_test(test_summary_salt_time_mapping),
        cmocka_unit_test(test_summary_large_model_estimates),
        cmocka_unit_test(test_summary_equilibration_warning),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
