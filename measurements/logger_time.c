/* Logger timestamps and local clocks: see logger_time.h. */
#define _GNU_SOURCE /* strptime, struct tm's tm_gmtoff (%z) */
#include "measurements/logger_time.h"

#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>

#define DAY 86400LL
/* POSIX seconds of 0001-01-01 and of 9999-12-31T23:59:59 */
#define T_MIN (-62135596800.0)
#define T_MAX 253402300799.0

/* ---- civil calendar (proleptic Gregorian), no time zone -------------------- */

/* Days since 1970-01-01 of y-m-d (H. Hinnant's days_from_civil). */
static long long days_from_civil(long long y, int m, int d)
{
    y -= m <= 2;
    const long long era = (y >= 0 ? y : y - 399) / 400;
    const long long yoe = y - era * 400;
    const long long doy = (153 * (m + (m > 2 ? -3 : 9)) + 2) / 5 + d - 1;
    const long long doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    return era * 146097 + doe - 719468;
}

static int days_in_month(long long y, int m)
{
    static const int dm[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
    const int leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
    return m == 2 ? 28 + leap : dm[m - 1];
}

static long long floor_div(long long a, long long b)
{
    long long q = a / b;
    return (a % b != 0 && (a < 0) != (b < 0)) ? q - 1 : q;
}

/* ---- time zones ------------------------------------------------------------- */

static const char *zone_dir(void)
{
    const char *d = getenv("TZDIR");
    return d && *d ? d : "/usr/share/zoneinfo";
}

/* The zone file of tz into path; PHC_ERR_INPUT when it is not one. */
static int zone_path(const char *tz, char *path, size_t size, phc_error *err)
{
    const char *dir = zone_dir();
    int ok = tz && *tz && tz[0] != '/' && !strstr(tz, "..") && strlen(tz) < 200;
    for (const char *c = tz; ok && *c; ++c)
        ok = isalnum((unsigned char)*c) || strchr("/_+-.", *c);
    if (ok) {
        struct stat st;
        char magic[4] = {0};
        FILE *f = NULL;
        snprintf(path, size, "%s/%s", dir, tz);
        ok = stat(path, &st) == 0 && S_ISREG(st.st_mode) && (f = fopen(path, "rb")) &&
             fread(magic, 1, 4, f) == 4 && memcmp(magic, "TZif", 4) == 0;
        if (f)
            fclose(f);
    }
    if (!ok)
        return phc_error_set(err, PHC_ERR_INPUT,
                             "time zone '%s' is not in %s (expected an IANA name such as Europe/Berlin or UTC)",
                             tz ? tz : "", dir);
    return PHC_OK;
}

int phc_time_zone_check(const char *tz, phc_error *err)
{
    char path[4096];
    return tz ? zone_path(tz, path, sizeof path, err) : PHC_OK;
}

/* The process's TZ, switched to one zone for the duration of a conversion
 * (glibc has no per-call zone API; see the header: not thread-safe). */
typedef struct zone_env {
    int active;  /* 0: UTC, nothing switched */
    int had_tz;
    char *saved; /* the previous TZ value */
} zone_env;

static int zone_enter(const char *tz, zone_env *z, phc_error *err)
{
    char path[4096], value[4100];
    int rc;
    memset(z, 0, sizeof *z);
    if (!tz)
        return PHC_OK;
    if ((rc = zone_path(tz, path, sizeof path, err)))
        return rc;
    const char *old = getenv("TZ");
    if (old && !(z->saved = strdup(old)))
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    z->had_tz = old != NULL;
    snprintf(value, sizeof value, ":%s", path); /* ":FILE": that file, no other lookup */
    if (setenv("TZ", value, 1) != 0) {
        free(z->saved);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    tzset();
    z->active = 1;
    return PHC_OK;
}

static void zone_leave(zone_env *z)
{
    if (!z->active)
        return;
    if (z->had_tz)
        setenv("TZ", z->saved, 1);
    else
        unsetenv("TZ");
    tzset();
    free(z->saved);
    z->active = 0;
}

/* UTC offset (s, east positive) of the active zone at POSIX second t. */
static long long offset_at(const zone_env *z, long long t)
{
    if (!z->active)
        return 0;
    time_t tt = (time_t)t;
    struct tm tm;
    if (!localtime_r(&tt, &tm))
        return 0;
    const long long local = days_from_civil(tm.tm_year + 1900LL, tm.tm_mon + 1, tm.tm_mday) * DAY +
                            tm.tm_hour * 3600LL + tm.tm_min * 60LL + tm.tm_sec;
    return local - t;
}

/* The instants (POSIX s, ascending) at which the zone's clock reads the
 * local civil second L (seconds since 1970-01-01 of the local calendar):
 * none in a skipped hour, two in a repeated one.  The offsets a day either
 * side cover any single transition near L. */
static int local_instants(const zone_env *z, long long L, long long out[3])
{
    long long offs[3] = {offset_at(z, L - DAY), offset_at(z, L), offset_at(z, L + DAY)};
    int n = 0;
    for (int i = 0; i < 3; ++i) {
        const long long t = L - offs[i];
        int dup = 0;
        for (int j = 0; j < n; ++j)
            dup |= out[j] == t;
        if (!dup && offset_at(z, t) == offs[i])
            out[n++] = t;
    }
    for (int i = 1; i < n; ++i) /* insertion sort of at most 3 */
        for (int j = i; j > 0 && out[j] < out[j - 1]; --j) {
            long long s = out[j];
            out[j] = out[j - 1];
            out[j - 1] = s;
        }
    return n;
}

/* In a skipped hour: the instant the clock jumps past L (the transition). */
static long long jump_instant(const zone_env *z, long long L)
{
    const long long before = offset_at(z, L - DAY), after = offset_at(z, L + DAY);
    long long lo = L - after, hi = L - before; /* offset(lo) = before, offset(hi) = after */
    if (lo > hi) {
        long long s = lo;
        lo = hi;
        hi = s;
    }
    while (hi - lo > 1) {
        const long long mid = lo + (hi - lo) / 2;
        if (offset_at(z, mid) == before)
            lo = mid;
        else
            hi = mid;
    }
    return hi;
}

/* ---- parsing ---------------------------------------------------------------- */

typedef struct civil {
    long long local; /* local civil seconds since 1970-01-01 */
    double frac;     /* fraction of a second, [0, 1) */
    int has_offset;
    long long offset; /* explicit UTC offset, s east */
} civil;

static int digits(const char **p, int n, int *out)
{
    int v = 0;
    for (int i = 0; i < n; ++i) {
        if (!isdigit((unsigned char)(*p)[i]))
            return 0;
        v = 10 * v + ((*p)[i] - '0');
    }
    *p += n;
    *out = v;
    return 1;
}

/* ".ddd" or ",ddd" */
static int fraction(const char **p, double *out)
{
    const char *s = *p;
    if ((*s != '.' && *s != ',') || !isdigit((unsigned char)s[1]))
        return 0;
    double f = 0, scale = 0.1;
    for (++s; isdigit((unsigned char)*s); ++s, scale *= 0.1)
        f += (*s - '0') * scale;
    *p = s;
    *out = f;
    return 1;
}

/* Builds the civil time; a reason (static text into why) when a field is out of range. */
static int civil_set(civil *c, long long y, int mo, int d, int h, int mi, int s, char *why, size_t wsize)
{
    if (y < 1 || y > 9999 || mo < 1 || mo > 12) {
        snprintf(why, wsize, " (year %lld, month %d)", y, mo);
        return 0;
    }
    if (d < 1 || d > days_in_month(y, mo)) {
        snprintf(why, wsize, " (day %d of month %d does not exist in %lld)", d, mo, y);
        return 0;
    }
    if (h > 23 || mi > 59 || s > 60) {
        snprintf(why, wsize, " (time %02d:%02d:%02d)", h, mi, s);
        return 0;
    }
    c->local = days_from_civil(y, mo, d) * DAY + h * 3600LL + mi * 60LL + s;
    return 1;
}

static int parse_iso(const char *text, civil *c, char *why, size_t wsize)
{
    const char *p = text;
    int y, mo, d, h = 0, mi = 0, s = 0;
    if (!digits(&p, 4, &y) || *p++ != '-' || !digits(&p, 2, &mo) || *p++ != '-' ||
        !digits(&p, 2, &d))
        return 0;
    if (*p == 'T' || *p == ' ') {
        ++p;
        while (*p == ' ')
            ++p;
        if (!digits(&p, 2, &h) || *p++ != ':' || !digits(&p, 2, &mi))
            return 0;
        if (*p == ':') {
            ++p;
            if (!digits(&p, 2, &s))
                return 0;
            fraction(&p, &c->frac);
        }
        while (*p == ' ')
            ++p;
        if (*p == 'Z') {
            c->has_offset = 1;
            ++p;
        } else if (*p == '+' || *p == '-') {
            const int sign = *p++ == '-' ? -1 : 1;
            int oh = 0, om = 0;
            if (!digits(&p, 2, &oh))
                return 0;
            if (*p == ':')
                ++p;
            if (isdigit((unsigned char)*p) && !digits(&p, 2, &om))
                return 0;
            if (oh > 18 || om > 59)
                return 0;
            c->has_offset = 1;
            c->offset = sign * (oh * 3600LL + om * 60LL);
        }
    }
    if (*p)
        return 0;
    return civil_set(c, y, mo, d, h, mi, s, why, wsize);
}

static int ends_with(const char *s, const char *tail)
{
    size_t a = strlen(s), b = strlen(tail);
    return a >= b && strcmp(s + a - b, tail) == 0;
}

static int parse_format(const char *text, const char *format, civil *c, char *why, size_t wsize)
{
    struct tm tm;
    memset(&tm, 0, sizeof tm);
    tm.tm_mday = 1;
    tm.tm_year = 70;
    const char *p = strptime(text, format, &tm);
    if (!p)
        return 0;
    if (ends_with(format, "%S") || ends_with(format, "%T"))
        fraction(&p, &c->frac);
    while (isspace((unsigned char)*p))
        ++p;
    if (*p) {
        snprintf(why, wsize, " (unexpected '%.40s' at the end)", p);
        return 0;
    }
    if (strstr(format, "%z")) {
        c->has_offset = 1;
        c->offset = tm.tm_gmtoff;
    }
    return civil_set(c, tm.tm_year + 1900LL, tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min,
                     tm.tm_sec, why, wsize);
}

static void describe_step(double s, char *out, size_t size)
{
    if (s < 120)
        snprintf(out, size, "%g s", s);
    else if (s < 2 * 3600.0)
        snprintf(out, size, "%g min", round(s / 6) / 10);
    else
        snprintf(out, size, "%.3g h", s / 3600);
}

int phc_logger_times(const phc_logger_clock *clock, const char *const *text,
                     const size_t *lines, size_t n, double *t, phc_error *err)
{
    const char *fmt = clock->format && *clock->format ? clock->format : NULL;
    const char *src = clock->source ? clock->source : "(data)";
    const char *what = clock->what ? clock->what : "time";
    zone_env z;
    int rc = zone_enter(clock->timezone, &z, err);
    if (rc)
        return rc;
    double prev = -INFINITY;
    for (size_t i = 0; i < n && !rc; ++i) {
        civil c;
        char why[160] = "";
        memset(&c, 0, sizeof c);
        const int ok = fmt ? parse_format(text[i], fmt, &c, why, sizeof why)
                           : parse_iso(text[i], &c, why, sizeof why);
        if (!ok) {
            if (fmt)
                rc = phc_error_set(err, PHC_ERR_INPUT, "%s:%zu: %s: '%s' does not match the format '%s'%s",
                                   src, lines[i], what, text[i], fmt, why);
            else
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: %s: '%s' does not match the format ISO 8601 (YYYY-MM-DD HH:MM:SS, "
                                   "optional fraction and Z or +HH:MM)%s; set `format:` for other layouts",
                                   src, lines[i], what, text[i], why);
            break;
        }
        long long cand[3];
        int nc;
        if (c.has_offset) {
            cand[0] = c.local - c.offset;
            nc = 1;
        } else if (z.active) {
            nc = local_instants(&z, c.local, cand);
        } else {
            cand[0] = c.local;
            nc = 1;
        }
        if (nc == 0) {
            rc = phc_error_set(err, PHC_ERR_INPUT,
                               "%s:%zu: %s: '%s' does not exist in %s (the clocks went forward there)",
                               src, lines[i], what, text[i], clock->timezone);
            break;
        }
        int pick = -1;
        for (int k = 0; k < nc && pick < 0; ++k)
            if ((double)cand[k] + c.frac >= prev)
                pick = k;
        if (pick < 0) {
            const double back = prev - ((double)cand[nc - 1] + c.frac);
            char step[64];
            describe_step(back, step, sizeof step);
            if (!z.active && !c.has_offset && back <= 3600)
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: %s: '%s' is %s before the previous reading (line %zu): the clock "
                                   "stepped back, which looks like the end of daylight saving; set `timezone:` "
                                   "to the logger's zone (e.g. timezone: Europe/Berlin)",
                                   src, lines[i], what, text[i], step, lines[i - 1]);
            else
                rc = phc_error_set(err, PHC_ERR_INPUT,
                                   "%s:%zu: %s: '%s' is %s before the previous reading (line %zu)%s%s; "
                                   "readings must be in time order",
                                   src, lines[i], what, text[i], step, lines[i - 1],
                                   z.active ? " even in " : "", z.active ? clock->timezone : "");
            break;
        }
        t[i] = prev = (double)cand[pick] + c.frac;
    }
    zone_leave(&z);
    return rc;
}

/* ---- local clocks ----------------------------------------------------------- */

static int check_time(double t, phc_error *err)
{
    if (!(t >= T_MIN && t <= T_MAX))
        return phc_error_set(err, PHC_ERR_INVALID, "time %g s is not a POSIX time of the years 1 to 9999", t);
    return PHC_OK;
}

int phc_local_clocks(const char *tz, const double *t_posix, size_t n, double *seconds,
                     phc_error *err)
{
    zone_env z;
    int rc = PHC_OK;
    for (size_t i = 0; i < n && !rc; ++i)
        rc = check_time(t_posix[i], err);
    if (rc || (rc = zone_enter(tz, &z, err)))
        return rc;
    for (size_t i = 0; i < n; ++i) {
        const double fl = floor(t_posix[i]);
        const long long s = (long long)fl;
        const long long local = s + offset_at(&z, s);
        seconds[i] = (double)(local - floor_div(local, DAY) * DAY) + (t_posix[i] - fl);
    }
    zone_leave(&z);
    return PHC_OK;
}

int phc_local_clock(const char *tz, double t_posix, double *seconds_since_local_midnight,
                    phc_error *err)
{
    return phc_local_clocks(tz, &t_posix, 1, seconds_since_local_midnight, err);
}

int phc_local_iso(const char *tz, double t_posix, char *buf, size_t size, phc_error *err)
{
    zone_env z;
    int rc;
    if ((rc = check_time(t_posix, err)) || (rc = zone_enter(tz, &z, err)))
        return rc;
    const long long s = (long long)floor(t_posix), off = offset_at(&z, s);
    const long long local = s + off, day = floor_div(local, DAY), sec = local - day * DAY;
    /* civil_from_days (H. Hinnant) */
    const long long zd = day + 719468, era = (zd >= 0 ? zd : zd - 146096) / 146097;
    const long long doe = zd - era * 146097;
    const long long yoe = (doe - doe / 1460 + doe / 36524 - doe / 146096) / 365;
    const long long doy = doe - (365 * yoe + yoe / 4 - yoe / 100), mp = (5 * doy + 2) / 153;
    const int d = (int)(doy - (153 * mp + 2) / 5 + 1), m = (int)(mp < 10 ? mp + 3 : mp - 9);
    const long long y = yoe + era * 400 + (m <= 2);
    const long long aoff = off < 0 ? -off : off;
    snprintf(buf, size, "%04lld-%02d-%02dT%02lld:%02lld:%02lld%c%02lld:%02lld", y, m, d, sec / 3600,
             sec / 60 % 60, sec % 60, off < 0 ? '-' : '+', aoff / 3600, aoff / 60 % 60);
    zone_leave(&z);
    return PHC_OK;
}

int phc_local_daily_times(const char *tz, double t0, double t1, double seconds_of_day,
                          double **times, size_t *n, phc_error *err)
{
    *times = NULL;
    *n = 0;
    int rc;
    if ((rc = check_time(t0 - DAY, err)) || (rc = check_time(t1 + DAY, err)))
        return rc;
    if (!(t0 <= t1) || !(seconds_of_day >= 0 && seconds_of_day < DAY))
        return phc_error_set(err, PHC_ERR_INVALID,
                             "phc_local_daily_times: expected t0 <= t1 and a time of day in [0, 86400) s, found %g, %g, %g",
                             t0, t1, seconds_of_day);
    zone_env z;
    if ((rc = zone_enter(tz, &z, err)))
        return rc;
    const double lo = t0 - DAY, hi = t1 + DAY;
    const long long s_lo = (long long)floor(lo), s_hi = (long long)floor(hi);
    const long long d0 = floor_div(s_lo + offset_at(&z, s_lo), DAY) - 1;
    const long long d1 = floor_div(s_hi + offset_at(&z, s_hi), DAY) + 1;
    const double sec_int = floor(seconds_of_day), frac = seconds_of_day - sec_int;
    double *out = malloc((size_t)(d1 - d0 + 1) * sizeof *out);
    if (!out) {
        zone_leave(&z);
        return phc_error_set(err, PHC_ERR_NOMEM, "out of memory");
    }
    size_t m = 0;
    for (long long d = d0; d <= d1; ++d) {
        const long long L = d * DAY + (long long)sec_int;
        long long cand[3];
        const double t = local_instants(&z, L, cand) > 0 ? (double)cand[0] + frac
                                                          : (double)jump_instant(&z, L);
        if (t >= lo && t <= hi)
            out[m++] = t;
    }
    zone_leave(&z);
    if (m == 0) {
        free(out);
        out = NULL;
    }
    *times = out;
    *n = m;
    return PHC_OK;
}
