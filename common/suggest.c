/* suggest: see suggest.h. */
#include "suggest.h"

#include <ctype.h>
#include <string.h>

size_t cdem_edit_distance(const char *a, const char *b) {
    enum { CAP = 63 };
    size_t la = strlen(a), lb = strlen(b);
    if (la > CAP)
        la = CAP;
    if (lb > CAP)
        lb = CAP;
    size_t prev[CAP + 1], cur[CAP + 1];
    for (size_t j = 0; j <= lb; j++)
        prev[j] = j;
    for (size_t i = 1; i <= la; i++) {
        cur[0] = i;
        for (size_t j = 1; j <= lb; j++) {
            size_t sub = prev[j - 1] +
                         (tolower((unsigned char)a[i - 1]) != tolower((unsigned char)b[j - 1]));
            size_t del = prev[j] + 1, ins = cur[j - 1] + 1;
            size_t best = sub < del ? sub : del;
            cur[j] = best < ins ? best : ins;
        }
        memcpy(prev, cur, (lb + 1) * sizeof prev[0]);
    }
    return prev[lb];
}

int cdem_suggest_close(size_t dist, const char *word) {
    size_t len = strlen(word);
    size_t limit = len / 3 > 2 ? len / 3 : 2;
    return dist <= limit;
}

const char *cdem_suggest(const char *word, const char *const *names, size_t n) {
    const char *best = NULL;
    size_t best_d = (size_t)-1;
    for (size_t i = 0; i < n; i++) {
        const size_t d = cdem_edit_distance(word, names[i]);
        if (d < best_d) {
            best_d = d;
            best = names[i];
        }
    }
    return best && cdem_suggest_close(best_d, word) ? best : NULL;
}
