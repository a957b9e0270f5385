/* governor: see governor.h. */
#include "governor.h"

#include <omp.h>
#include <stdlib.h>
#include <string.h>

static void use(cdem_governor *g, int threads) {
    if (g->current != threads)
        omp_set_num_threads(threads);
    g->current = threads;
}

void cdem_governor_init(cdem_governor *g, double now, long step) {
    memset(g, 0, sizeof *g);
    g->allowed = omp_get_max_threads();
    const char *off = getenv("CDEM_THREAD_GOVERNOR");
    g->enabled = g->allowed > 1 && !(off && strcmp(off, "off") == 0);
    g->chosen = g->current = g->allowed;
    g->phase = CDEM_GOVERNOR_RUN;
    g->interval = GOVERNOR_MIN_S;
    g->t_next_probe = now + GOVERNOR_FIRST_S;
    g->step_last = step;
}

void cdem_governor_finish(cdem_governor *g) {
    if (g->enabled)
        use(g, g->allowed);
}

/* Adds a timed step to the open window; returns the window's time per step once it is long
 * enough, a negative value before. */
static double window_per_step(cdem_governor *g, double step_seconds) {
    if (!(step_seconds >= 0.0))
        return -1.0; /* not timed (cannot happen while a window is open) */
    g->window_seconds += step_seconds;
    g->window_steps++;
    if (g->window_steps < GOVERNOR_WINDOW_MIN_STEPS || g->window_seconds < GOVERNOR_WINDOW_S)
        return -1.0;
    return g->window_seconds / (double)g->window_steps;
}

static void start_window(cdem_governor *g) {
    g->window_seconds = 0.0;
    g->window_steps = 0;
}

int cdem_governor_after_step(cdem_governor *g, long step, double now, double step_seconds) {
    if (!g->enabled)
        return 0;
    if (g->chosen == 1 && g->current == 1) /* by choice, not in a probe of one thread */
        g->steps_on_one += step - g->step_last;
    g->step_last = step;
    switch (g->phase) {
    case CDEM_GOVERNOR_RUN:
        if (now >= 0.0 && now >= g->t_next_probe) {
            g->phase = CDEM_GOVERNOR_TIME;
            start_window(g);
        }
        return 0;
    case CDEM_GOVERNOR_TIME: {
        const double a = window_per_step(g, step_seconds);
        if (a < 0.0)
            return 0;
        g->per_step_chosen = a;
        g->phase = CDEM_GOVERNOR_PROBE;
        use(g, g->chosen == 1 ? g->allowed : 1);
        start_window(g);
        return 0;
    }
    case CDEM_GOVERNOR_PROBE: {
        const double b = window_per_step(g, step_seconds);
        if (b < 0.0)
            return 0;
        g->probes++;
        const int change = b < GOVERNOR_SWITCH_RATIO * g->per_step_chosen;
        if (change) {
            g->chosen = g->current;
            g->changes++;
            g->interval = GOVERNOR_MIN_S;
        } else {
            use(g, g->chosen);
            g->interval = g->interval * 2.0 > GOVERNOR_MAX_S ? GOVERNOR_MAX_S : g->interval * 2.0;
        }
        g->phase = CDEM_GOVERNOR_RUN;
        /* (now is read after every timed step, so it is known here; a caller that did not
         * read it gets the next probe as soon as it does) */
        g->t_next_probe = now >= 0.0 ? now + g->interval : 0.0;
        return change;
    }
    }
    return 0;
}
