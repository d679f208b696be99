/* Solid shapes as a signed distance (shapes.h). */
#include "grid/shapes.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define SHAPES_ALLOWED                                                                          \
    "allowed: 'circle A B R', 'rectangle A0 B0 A1 B1' or 'slope AC BR THETA R', joined by ';'"

/* Reads up to want numbers from s; returns how many, or -1 on a word that is
 * not a finite number. */
static int read_numbers(const char *s, double *v, int want)
{
    int got = 0;
    for (;;) {
        while (isspace((unsigned char)*s))
            s++;
        if (!*s)
            return got;
        char *end;
        double x = strtod(s, &end);
        if (end == s || !isfinite(x) || (*end && !isspace((unsigned char)*end)))
            return -1;
        if (got == want)
            return want + 1; /* too many */
        v[got++] = x;
        s = end;
    }
}

static int parse_one(struct shape *sh, char *item, char *msg, size_t msglen)
{
    char *s = item;
    while (isspace((unsigned char)*s))
        s++;
    size_t wl = 0;
    while (s[wl] && !isspace((unsigned char)s[wl]))
        wl++;
    int want;
    if (wl == 6 && strncmp(s, "circle", 6) == 0) {
        sh->kind = SHAPE_CIRCLE;
        want = 3;
    } else if (wl == 9 && strncmp(s, "rectangle", 9) == 0) {
        sh->kind = SHAPE_RECTANGLE;
        want = 4;
    } else if (wl == 5 && strncmp(s, "slope", 5) == 0) {
        sh->kind = SHAPE_SLOPE;
        want = 4;
    } else {
        snprintf(msg, msglen, "unknown shape '%.*s' (%s)", (int)(wl < 40 ? wl : 40), s,
                 SHAPES_ALLOWED);
        return -1;
    }
    int got = read_numbers(s + wl, sh->v, want);
    if (got != want) {
        snprintf(msg, msglen, "'%.60s' needs %d numbers (%s)", s, want, SHAPES_ALLOWED);
        return -1;
    }
    if (sh->kind == SHAPE_CIRCLE && !(sh->v[2] > 0.0)) {
        snprintf(msg, msglen, "'%.60s': the radius must be > 0 (%s)", s, SHAPES_ALLOWED);
        return -1;
    }
    if (sh->kind == SHAPE_SLOPE && !(sh->v[2] > 0.0 && sh->v[2] < 1.5707963267948966 &&
                                     sh->v[3] > 0.0)) {
        snprintf(msg, msglen, "'%.60s': the angle THETA must be in (0, pi/2) radians and the "
                              "radius R > 0 (%s)", s, SHAPES_ALLOWED);
        return -1;
    }
    if (sh->kind == SHAPE_RECTANGLE) {
        if (!(sh->v[0] != sh->v[2] && sh->v[1] != sh->v[3])) {
            snprintf(msg, msglen, "'%.60s': the corners must differ in both coordinates (%s)", s,
                     SHAPES_ALLOWED);
            return -1;
        }
        double a0 = fmin(sh->v[0], sh->v[2]), a1 = fmax(sh->v[0], sh->v[2]);
        double b0 = fmin(sh->v[1], sh->v[3]), b1 = fmax(sh->v[1], sh->v[3]);
        sh->v[0] = a0, sh->v[1] = b0, sh->v[2] = a1, sh->v[3] = b1;
    }
    return 0;
}

int shapes_parse(struct shape_set *set, const char *text, char *msg, size_t msglen)
{
    char buf[1024];
    if (strlen(text) >= sizeof buf) {
        snprintf(msg, msglen, "longer than %zu characters", sizeof buf - 1);
        return -1;
    }
    snprintf(buf, sizeof buf, "%s", text);
    set->n = 0;
    char *save = NULL;
    for (char *item = strtok_r(buf, ";", &save); item; item = strtok_r(NULL, ";", &save)) {
        const char *t = item;
        while (isspace((unsigned char)*t))
            t++;
        if (!*t)
            continue; /* "circle ...;" or blanks */
        if (set->n == SHAPES_MAX) {
            snprintf(msg, msglen, "more than %d shapes (%s)", SHAPES_MAX, SHAPES_ALLOWED);
            return -1;
        }
        if (parse_one(&set->s[set->n], item, msg, msglen) != 0)
            return -1;
        set->n++;
    }
    return 0;
}

double shape_slope_bed(const struct shape *sh, double a)
{
    double ac = sh->v[0], br = sh->v[1], th = sh->v[2], r = sh->v[3];
    double at = ac - r * sin(th), bt = br + r * (1.0 - cos(th));
    if (a >= ac)
        return br;
    if (a >= at)
        return br + r - sqrt(fmax(r * r - (a - ac) * (a - ac), 0.0));
    return bt + (at - a) * tan(th);
}

/* The slope's signed distance: the nearest of its three pieces (the floor's
 * half-line, the arc, the incline's half-line), negative below the bed. */
static double slope_distance(const struct shape *sh, double a, double b)
{
    double ac = sh->v[0], br = sh->v[1], th = sh->v[2], r = sh->v[3];
    double at = ac - r * sin(th), bt = br + r * (1.0 - cos(th)), bc = br + r;
    double d = a >= ac ? fabs(b - br) : hypot(a - ac, b - br);
    double t = -(a - at) * cos(th) + (b - bt) * sin(th); /* along the incline, up */
    d = fmin(d, t <= 0.0 ? hypot(a - at, b - bt) : fabs((a - at) * sin(th) + (b - bt) * cos(th)));
    /* the arc runs from the angle -pi/2 - theta (the incline's end) to -pi/2 */
    double phi = atan2(b - bc, a - ac);
    const double half_pi = 1.5707963267948966;
    if (phi <= -half_pi && phi >= -half_pi - th)
        d = fmin(d, fabs(hypot(a - ac, b - bc) - r));
    return b < shape_slope_bed(sh, a) ? -d : d;
}

/* Signed distance to one shape's surface, negative inside it. */
static double one_distance(const struct shape *sh, double a, double b)
{
    if (sh->kind == SHAPE_CIRCLE)
        return hypot(a - sh->v[0], b - sh->v[1]) - sh->v[2];
    if (sh->kind == SHAPE_SLOPE)
        return slope_distance(sh, a, b);
    /* the box's exact distance: outside, to the nearest point; inside, minus
     * the distance to the nearest side */
    double ca = 0.5 * (sh->v[0] + sh->v[2]), cb = 0.5 * (sh->v[1] + sh->v[3]);
    double qa = fabs(a - ca) - 0.5 * (sh->v[2] - sh->v[0]);
    double qb = fabs(b - cb) - 0.5 * (sh->v[3] - sh->v[1]);
    return hypot(fmax(qa, 0.0), fmax(qb, 0.0)) + fmin(fmax(qa, qb), 0.0);
}

double shape_distance(const struct shape_set *set, const double x[3])
{
    /* the union's distance is the smallest (exact outside the union, and
     * inside it up to the overlap of shapes, where only its sign is used) */
    double d = INFINITY;
    for (int i = 0; i < set->n; i++)
        d = fmin(d, one_distance(&set->s[i], x[set->plane_a], x[set->plane_b]));
    return set->invert ? -d : d;
}

void shape_normal(const struct shape_set *set, const double x[3], double n[3])
{
    /* central differences of the distance at a step far below any grid's */
    double e = 1e-7;
    for (int i = 0; i < set->n; i++)
        e = fmin(e, 1e-6 * (set->s[i].kind == SHAPE_CIRCLE  ? set->s[i].v[2]
                            : set->s[i].kind == SHAPE_SLOPE ? set->s[i].v[3]
                                                            : set->s[i].v[2] - set->s[i].v[0]));
    double g[3] = {0.0, 0.0, 0.0}, y[3];
    int dirs[2] = {set->plane_a, set->plane_b};
    for (int k = 0; k < 2; k++) {
        int d = dirs[k];
        memcpy(y, x, sizeof y);
        y[d] = x[d] + e;
        double dp = shape_distance(set, y);
        y[d] = x[d] - e;
        g[d] = (dp - shape_distance(set, y)) / (2.0 * e);
    }
    double m = sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    for (int d = 0; d < 3; d++)
        n[d] = m > 0.0 ? g[d] / m : 0.0;
}

void shapes_set_plane(struct shape_set *set, int plane, int invert)
{
    static const int planes[3][2] = {{0, 2}, {0, 1}, {1, 2}};
    set->plane_a = planes[plane][0];
    set->plane_b = planes[plane][1];
    set->invert = invert;
}

/* 1 when shape sh has a point strictly inside [0, la] x [0, lb]. */
static int reaches_box(const struct shape *sh, double la, double lb)
{
    if (sh->kind == SHAPE_SLOPE) /* the bed is highest at a = 0 */
        return la > 0.0 && lb > 0.0 && shape_slope_bed(sh, 0.0) > 0.0;
    if (sh->kind == SHAPE_RECTANGLE)
        return sh->v[0] < la && sh->v[2] > 0.0 && sh->v[1] < lb && sh->v[3] > 0.0;
    /* the circle's distance to the nearest point of the box */
    double da = fmax(fmax(-sh->v[0], sh->v[0] - la), 0.0);
    double db = fmax(fmax(-sh->v[1], sh->v[1] - lb), 0.0);
    return hypot(da, db) < sh->v[2];
}

int shapes_outside_box(const struct shape_set *set, const double len[3])
{
    for (int i = 0; i < set->n; i++)
        if (!reaches_box(&set->s[i], len[set->plane_a], len[set->plane_b]))
            return i;
    return -1;
}

int shapes_connect(const struct shape_set *set, const int n[3], const double len[3], int axis)
{
    int a = set->plane_a, b = set->plane_b, na = n[a], nb = n[b];
    size_t cells = (size_t)na * (size_t)nb;
    unsigned char *fluid = malloc(cells);
    int *queue = malloc(cells * sizeof *queue);
    if (!fluid || !queue) {
        free(fluid);
        free(queue);
        return -1;
    }
    int any = 0;
    for (int i = 0; i < na; i++)
        for (int j = 0; j < nb; j++) {
            double x[3] = {0.0, 0.0, 0.0};
            x[a] = (i + 0.5) * len[a] / na;
            x[b] = (j + 0.5) * len[b] / nb;
            fluid[(size_t)i * nb + j] = shape_distance(set, x) > 0.0;
            any |= fluid[(size_t)i * nb + j];
        }
    int joined = 0;
    if (axis != a && axis != b) {
        joined = any; /* extruded along axis: every fluid cell runs through */
    } else {
        /* breadth-first from the fluid cells at the low face (marked 2) */
        size_t head = 0, tail = 0;
        int along_a = axis == a, nl = along_a ? na : nb;
        for (int i = 0; i < na; i++)
            for (int j = 0; j < nb; j++) {
                size_t p = (size_t)i * nb + j;
                if (fluid[p] && (along_a ? i : j) == 0) {
                    fluid[p] = 2;
                    queue[tail++] = (int)p;
                }
            }
        static const int step[4][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
        while (head < tail && !joined) {
            int p = queue[head++], i = p / nb, j = p % nb;
            if ((along_a ? i : j) == nl - 1)
                joined = 1;
            for (int s = 0; s < 4; s++) {
                int i2 = i + step[s][0], j2 = j + step[s][1];
                if (i2 < 0 || i2 >= na || j2 < 0 || j2 >= nb)
                    continue;
                size_t q = (size_t)i2 * nb + j2;
                if (fluid[q] == 1) {
                    fluid[q] = 2;
                    queue[tail++] = (int)q;
                }
            }
        }
    }
    free(fluid);
    free(queue);
    return joined;
}

/* 1 when the centre of the face of cell (i, j) on side (-1 low, +1 high)
 * along the plane's direction k (0: a, 1: b) lies in the fluid. */
static int face_open(const struct shape_set *set, const double h[2], int i, int j, int k,
                     int side)
{
    double x[3] = {0.0, 0.0, 0.0};
    x[set->plane_a] = (k == 0 ? i + (side > 0) : i + 0.5) * h[0];
    x[set->plane_b] = (k == 1 ? j + (side > 0) : j + 0.5) * h[1];
    return shape_distance(set, x) > 0.0;
}

int shapes_regions(const struct shape_set *set, const int n[3], const double len[3],
                   const int periodic[3], const int fixed[3][2], int *regions, int *floating)
{
    const int a = set->plane_a, b = set->plane_b, e = 3 - a - b;
    const int na = n[a], nb = n[b], dir[2] = {a, b}, ncell[2] = {na, nb};
    const double h[2] = {len[a] / na, len[b] / nb};
    size_t cells = (size_t)na * (size_t)nb;
    unsigned char *seen = calloc(cells, 1);
    int *queue = malloc(cells * sizeof *queue);
    if (!seen || !queue) {
        free(seen);
        free(queue);
        return -1;
    }
    *regions = *floating = 0;
    for (size_t start = 0; start < cells; start++) {
        int i0 = (int)(start / (size_t)nb), j0 = (int)(start % (size_t)nb);
        if (seen[start])
            continue;
        double xc[3] = {0.0, 0.0, 0.0};
        xc[a] = (i0 + 0.5) * h[0];
        xc[b] = (j0 + 0.5) * h[1];
        int live = shape_distance(set, xc) > 0.0;
        for (int k = 0; k < 2 && !live; k++)
            for (int side = -1; side <= 1 && !live; side += 2) {
                int at = (k == 0 ? i0 : j0) + side, nk = k == 0 ? na : nb;
                live = (periodic[dir[k]] || (at >= 0 && at < nk)) &&
                       face_open(set, h, i0, j0, k, side);
            }
        if (!live)
            continue;
        /* breadth-first through the open faces */
        size_t head = 0, tail = 0;
        int held = 0;
        seen[start] = 1;
        queue[tail++] = (int)start;
        while (head < tail) {
            int p = queue[head++], i = p / nb, j = p % nb;
            xc[a] = (i + 0.5) * h[0];
            xc[b] = (j + 0.5) * h[1];
            /* the extrusion's faces lie at the cell's centre in the plane */
            if (shape_distance(set, xc) > 0.0 && (fixed[e][0] || fixed[e][1]))
                held = 1;
            for (int k = 0; k < 2; k++)
                for (int side = -1; side <= 1; side += 2) {
                    if (!face_open(set, h, i, j, k, side))
                        continue;
                    int idx[2] = {i, j};
                    idx[k] += side;
                    if (idx[k] < 0 || idx[k] >= ncell[k]) {
                        if (!periodic[dir[k]]) {
                            held |= fixed[dir[k]][side > 0];
                            continue;
                        }
                        idx[k] = (idx[k] + ncell[k]) % ncell[k];
                    }
                    size_t q = (size_t)idx[0] * nb + idx[1];
                    if (!seen[q]) {
                        seen[q] = 1;
                        queue[tail++] = (int)q;
                    }
                }
        }
        ++*regions;
        *floating += !held;
    }
    free(seen);
    free(queue);
    return 0;
}
