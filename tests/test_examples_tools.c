/* The examples' Python tools, run as the example Makefiles run them (/usr/bin/python3 with
 * Debian's Pillow): examples/montage.py keeps every colour of its inputs (issue 35: it saved
 * a palette of 256 to 32 colours, which posterised the colour bars of calibration.png,
 * fig14.png and fig7.png); and every example folder's Makefile has a `quick` target (a dry
 * run of it, no simulation). Runs from the repository root; scratch in $CDEM_TEST_TMP. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include <cmocka.h>

#include <glob.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "scratch.h"

/* Runs CMD (stdout and stderr) into OUT; returns its exit status. */
static int run_cmd(const char *cmd, char *out, size_t cap) {
    FILE *p = popen(cmd, "r");
    assert_non_null(p);
    size_t n = fread(out, 1, cap - 1, p);
    out[n] = '\0';
    return pclose(p);
}

/* Two inputs with smooth gradients of 1000 colours each (like a colour bar) tiled by
 * montage.py: the result is an RGB PNG with far more than a palette's 256 colours. */
static void test_examples_montage_keeps_the_gradients(void **unused) {
    (void)unused;
    char a[1024], b[1024], out_png[1024], cmd[8192];
    static char out[8192];
    scratch_path(a, sizeof a, "montage_a.png");
    scratch_path(b, sizeof b, "montage_b.png");
    scratch_path(out_png, sizeof out_png, "montage_out.png");
    snprintf(cmd, sizeof cmd,
             "/usr/bin/python3 - '%s' '%s' <<'EOF' 2>&1\n"
             "import sys\n"
             "from PIL import Image\n"
             "for k, path in enumerate(sys.argv[1:]):\n"
             "    im = Image.new('RGB', (1000, 60))\n"
             "    for x in range(1000):\n"
             "        c = (x * 255 // 999, (x * 7 + 80 * k) %% 256, 255 - x * 255 // 999)\n"
             "        for y in range(60):\n"
             "            im.putpixel((x, y), c)\n"
             "    im.save(path)\n"
             "EOF",
             a, b);
    assert_int_equal(run_cmd(cmd, out, sizeof out), 0);
    snprintf(cmd, sizeof cmd,
             "/usr/bin/python3 examples/montage.py '%s' 1 --title one '%s' --title two '%s' "
             "2>&1 && /usr/bin/python3 -c \"import sys; from PIL import Image; "
             "im = Image.open(sys.argv[1]); "
             "print(im.mode, len(im.convert('RGB').getcolors(1 << 24)))\" '%s'",
             out_png, a, b, out_png);
    assert_int_equal(run_cmd(cmd, out, sizeof out), 0);
    char mode[16] = "";
    int colours = 0;
    if (sscanf(out, "%15s %d", mode, &colours) != 2)
        fail_msg("unexpected output: %s", out);
    printf("    montage: mode %s, %d colours\n", mode, colours);
    assert_string_equal(mode, "RGB");
    assert_true(colours > 1000); /* the palette kept at most 256 */
    remove(a);
    remove(b);
    remove(out_png);
}

/* Every examples/FOLDER/Makefile has a `quick` target meaning QUICK=1 (issue 46, item 13a:
 * `make -C examples/inversion quick` had no such target): `make -n quick` (a dry run: no
 * simulation, no folder made) succeeds and its runs go to out-quick/. */
static void test_examples_every_folder_has_quick(void **unused) {
    (void)unused;
    glob_t gl;
    assert_int_equal(glob("examples/*/Makefile", 0, NULL, &gl), 0);
    assert_true(gl.gl_pathc >= 10);
    const char *build = getenv("CDEM_BUILD");
    static char out[1 << 16];
    for (size_t k = 0; k < gl.gl_pathc; k++) {
        char dir[1024], cmd[4096];
        snprintf(dir, sizeof dir, "%.*s", (int)(strlen(gl.gl_pathv[k]) - strlen("/Makefile")),
                 gl.gl_pathv[k]);
        snprintf(cmd, sizeof cmd, "env -u MAKEFLAGS -u MAKELEVEL make -n -C '%s' quick%s%s 2>&1",
                 dir, build && *build ? " BUILD=" : "", build && *build ? build : "");
        const int st = run_cmd(cmd, out, sizeof out);
        if (st != 0)
            fail_msg("make -n -C %s quick failed (status %d):\n%.2000s", dir, st, out);
        if (!strstr(out, "out-quick/"))
            fail_msg("make -n -C %s quick writes nothing to out-quick/ (not QUICK=1?):\n%.2000s",
                     dir, out);
    }
    printf("    %zu example folders have a quick target\n", gl.gl_pathc);
    globfree(&gl);
}

int main(void) {
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_examples_montage_keeps_the_gradients),
        cmocka_unit_test(test_examples_every_folder_has_quick),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
