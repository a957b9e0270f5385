/* suggest: the "did you mean ...?" of every name a user types: parameter keys and sections,
 * cdem-run's options, cdem-strain's subcommands, options and quantities. One rule for both
 * programs: the distance is Levenshtein's over the first 63 characters, letters compared
 * without case (a user's "Width" or "RENDER" is a spelling, not another name), and a name is
 * offered only when it is close for the length of what was typed (cdem_suggest_close).
 * Ownership: nothing is kept; the names are the caller's. Thread safety: pure functions. */
#ifndef CDEM_SUGGEST_H
#define CDEM_SUGGEST_H

#include <stddef.h>

/* Edit distance of a and b (insertions, deletions, substitutions; case ignored), each cut to
 * its first 63 characters. No allocation. */
size_t cdem_edit_distance(const char *a, const char *b);

/* 1 when a known name at distance dist from the typed word is worth offering: dist is at
 * most a third of the word's length, and never more than 2 for a short word. */
int cdem_suggest_close(size_t dist, const char *word);

/* The name of names[0..n) closest to word (the first of equals) when it is close
 * (cdem_suggest_close), else NULL. */
const char *cdem_suggest(const char *word, const char *const *names, size_t n);

#endif
