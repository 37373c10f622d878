/* Unit tests for measurements/logger_time.c: logger timestamps through a
 * time zone, the daylight-saving steps, and the local-clock helpers.
 *
 * Reference instants were computed outside phytocal with GNU date
 * (`date -u -d 2024-10-24T11:05:07Z +%s`) and by hand from the EU rule:
 * summer time (CEST, UTC+2) in Europe/Berlin runs from 2024-03-31 01:00 UTC
 * (02:00 CET -> 03:00 CEST) to 2024-10-27 01:00 UTC (03:00 CEST -> 02:00 CET). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "measurements/logger_time.h"

#define H 3600.0
#define T_1024_1105_07 1729767907.0 /* 2024-10-24T11:05:07Z */
#define T_0331_0100 1711846800.0    /* 2024-03-31T01:00:00Z: clocks go forward */
#define T_1027_0000 1729987200.0    /* 2024-10-27T00:00:00Z */
#define T_0330_0600 1711778400.0    /* 2024-03-30T06:00:00Z */
#define T_0701_0500 1719810000.0    /* 2024-07-01T05:00:00Z */

static int series(const char *format, const char *tz, const char *const *text, size_t n, double *t,
                  phc_error *err)
{
    size_t lines[16];
    for (size_t i = 0; i < n; ++i)
        lines[i] = i + 2; /* a header on line 1 */
    phc_logger_clock c = {format, tz, "log.csv", "columns 'Date' and 'Time'"};
    phc_error_clear(err);
    return phc_logger_times(&c, text, lines, n, t, err);
}

static double one(const char *format, const char *tz, const char *text)
{
    double t = NAN;
    phc_error err;
    if (series(format, tz, &text, 1, &t, &err)) {
        fprintf(stderr, "'%s': %s\n", text, err.message);
        return NAN;
    }
    return t;
}

static void test_iso(void)
{
    /* the ISO forms, as written (UTC) or with an explicit offset */
    CHECK_NEAR(one(NULL, NULL, "2024-10-24T11:05:07"), T_1024_1105_07, 0, 0);
    CHECK_NEAR(one(NULL, NULL, "2024-10-24 11:05:07"), T_1024_1105_07, 0, 0);
    CHECK_NEAR(one("", NULL, "2024-10-24T11:05:07Z"), T_1024_1105_07, 0, 0);
    CHECK_NEAR(one(NULL, NULL, "2024-10-24T13:05:07+02:00"), T_1024_1105_07, 0, 0);
    CHECK_NEAR(one(NULL, NULL, "2024-10-24T08:05:07-0300"), T_1024_1105_07, 0, 0);
    CHECK_NEAR(one(NULL, NULL, "2024-10-24T11:05:07.25Z"), T_1024_1105_07 + 0.25, 1e-6, 0);
    CHECK_NEAR(one(NULL, NULL, "2024-10-24 11:05"), T_1024_1105_07 - 7, 0, 0);
    /* a zone: 13:05:07 CEST is 11:05:07 UTC; an explicit offset wins over the zone */
    CHECK_NEAR(one(NULL, "Europe/Berlin", "2024-10-24 13:05:07.5"), T_1024_1105_07 + 0.5, 1e-6, 0);
    CHECK_NEAR(one(NULL, "Europe/Berlin", "2024-10-24T11:05:07Z"), T_1024_1105_07, 0, 0);
    CHECK_NEAR(one(NULL, "UTC", "2024-10-24T11:05:07"), T_1024_1105_07, 0, 0);
    /* winter: 07:00 CET = 06:00 UTC */
    CHECK_NEAR(one(NULL, "Europe/Berlin", "2024-03-30 07:00:00"), T_0330_0600, 0, 0);
}

static void test_day_first(void)
{
    const char *f = "%d/%m/%Y %H:%M:%S";
    CHECK_NEAR(one(f, "Europe/Berlin", "24/10/2024 13:05:07"), T_1024_1105_07, 0, 0);
    CHECK_NEAR(one(f, NULL, "24/10/2024 11:05:07"), T_1024_1105_07, 0, 0);
    CHECK_NEAR(one(f, NULL, "24/10/2024 11:05:07.75"), T_1024_1105_07 + 0.75, 1e-6, 0);
    CHECK_NEAR(one("%d.%m.%Y %H:%M", NULL, "24.10.2024 11:05"), T_1024_1105_07 - 7, 0, 0);
    CHECK_NEAR(one("%m/%d/%Y %I:%M:%S %p", NULL, "10/24/2024 11:05:07 AM"), T_1024_1105_07, 0, 0);
    CHECK_NEAR(one("%Y-%m-%d %H:%M:%S%z", "Europe/Berlin", "2024-10-24 11:05:07+0000"),
               T_1024_1105_07, 0, 0);
}

static void test_spring_forward(void)
{
    const char *f = "%d/%m/%Y %H:%M:%S";
    const char *ok[] = {"31/03/2024 01:50:00", "31/03/2024 03:00:00", "31/03/2024 03:10:00"};
    double t[3];
    phc_error err;
    CHECK(series(f, "Europe/Berlin", ok, 3, t, &err) == PHC_OK);
    CHECK_NEAR(t[0], T_0331_0100 - 600, 0, 0); /* 01:50 CET = 00:50 UTC */
    CHECK_NEAR(t[1], T_0331_0100, 0, 0);       /* 03:00 CEST = 01:00 UTC */
    CHECK_NEAR(t[2] - t[1], 600, 0, 0);
    /* 02:30 does not exist that night */
    const char *gap[] = {"31/03/2024 01:50:00", "31/03/2024 02:30:00"};
    CHECK(series(f, "Europe/Berlin", gap, 2, t, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "log.csv:3: columns 'Date' and 'Time': '31/03/2024 02:30:00'");
    CHECK_STR_CONTAINS(err.message, "does not exist in Europe/Berlin");
}

static void test_fall_back(void)
{
    const char *f = "%d/%m/%Y %H:%M:%S";
    /* every 20 min through the repeated hour: 02:20 and 02:40 occur twice */
    const char *text[] = {"27/10/2024 02:00:00", "27/10/2024 02:20:00", "27/10/2024 02:40:00",
                          "27/10/2024 02:00:00", "27/10/2024 02:20:00", "27/10/2024 02:40:00",
                          "27/10/2024 03:00:00"};
    double t[7];
    phc_error err;
    CHECK(series(f, "Europe/Berlin", text, 7, t, &err) == PHC_OK);
    for (int i = 0; i < 7; ++i) /* 02:00 CEST = 00:00 UTC, then every 20 min */
        CHECK_NEAR(t[i], T_1027_0000 + i * 1200.0, 0, 0);
    /* 02:30 twice, an hour apart: the first CEST, the second CET */
    const char *twice[] = {"27/10/2024 02:30:00", "27/10/2024 02:50:00", "27/10/2024 02:10:00",
                           "27/10/2024 02:30:00"};
    CHECK(series(f, "Europe/Berlin", twice, 4, t, &err) == PHC_OK);
    CHECK_NEAR(t[0], T_1027_0000 + 0.5 * H, 0, 0);
    CHECK_NEAR(t[1], T_1027_0000 + 0.5 * H + 1200, 0, 0);
    CHECK_NEAR(t[2], T_1027_0000 + 1 * H + 600, 0, 0);
    CHECK_NEAR(t[3], T_1027_0000 + 1.5 * H, 0, 0);
    /* a repeated time read twice in a row stays one instant (readings within a minute) */
    const char *same[] = {"27/10/2024 02:30", "27/10/2024 02:30", "27/10/2024 02:31"};
    CHECK(series("%d/%m/%Y %H:%M", "Europe/Berlin", same, 3, t, &err) == PHC_OK);
    CHECK_NEAR(t[1], t[0], 0, 0);
    CHECK_NEAR(t[2] - t[0], 60, 0, 0);
    /* without a zone the step back is an error naming the line and the cure */
    CHECK(series(f, NULL, twice, 4, t, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "log.csv:4: columns 'Date' and 'Time': '27/10/2024 02:10:00'");
    CHECK_STR_CONTAINS(err.message, "40 min before the previous reading (line 3)");
    CHECK_STR_CONTAINS(err.message, "daylight saving");
    CHECK_STR_CONTAINS(err.message, "timezone:");
    /* a step back of more than an hour is disorder, even with a zone */
    const char *back[] = {"27/10/2024 06:00:00", "27/10/2024 03:00:00"};
    CHECK(series(f, "Europe/Berlin", back, 2, t, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "log.csv:3:");
    CHECK_STR_CONTAINS(err.message, "3 h before the previous reading (line 2) even in Europe/Berlin");
    CHECK_STR_CONTAINS(err.message, "time order");
}

static void test_zones(void)
{
    phc_error err;
    double t;
    const char *text = "2024-10-24 13:05:07";
    CHECK(phc_time_zone_check("Europe/Berlin", &err) == PHC_OK);
    CHECK(phc_time_zone_check("UTC", &err) == PHC_OK);
    CHECK(phc_time_zone_check(NULL, &err) == PHC_OK);
    const char *bad[] = {"Europe/Berln", "../zoneinfo/UTC", "/etc/localtime", "", "Europe",
                         "zone.tab", "Europe/Berlin "};
    for (size_t i = 0; i < sizeof bad / sizeof *bad; ++i) {
        phc_error_clear(&err);
        CHECK(phc_time_zone_check(bad[i], &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "is not in");
    }
    CHECK(series(NULL, "Europe/Berln", &text, 1, &t, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "time zone 'Europe/Berln' is not in");
    double s;
    CHECK(phc_local_clock("Mars/Olympus", 0, &s, &err) == PHC_ERR_INPUT);
    /* the caller's TZ is restored */
    setenv("TZ", "America/New_York", 1);
    CHECK_NEAR(one(NULL, "Europe/Berlin", text), T_1024_1105_07, 0, 0);
    CHECK(getenv("TZ") && strcmp(getenv("TZ"), "America/New_York") == 0);
    unsetenv("TZ");
    CHECK_NEAR(one(NULL, "Europe/Berlin", text), T_1024_1105_07, 0, 0);
    CHECK(getenv("TZ") == NULL);
}

static void test_bad_dates(void)
{
    const char *f = "%d/%m/%Y %H:%M:%S";
    phc_error err;
    double t[2];
    const char *feb[] = {"30/01/2024 10:00:00", "31/02/2024 10:00:00"};
    CHECK(series(f, NULL, feb, 2, t, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "log.csv:3: columns 'Date' and 'Time': '31/02/2024 10:00:00' "
                                    "does not match the format '%d/%m/%Y %H:%M:%S'");
    CHECK_STR_CONTAINS(err.message, "day 31 of month 2 does not exist in 2024");
    const char *leap[] = {"29/02/2023 10:00:00"};
    CHECK(series(f, NULL, leap, 1, t, &err) == PHC_ERR_INPUT);
    CHECK(one(f, NULL, "29/02/2024 10:00:00") > 0);
    const char *sep[] = {"24.10.2024 10:00:00"};
    CHECK(series(f, NULL, sep, 1, t, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "log.csv:2:");
    CHECK_STR_CONTAINS(err.message, "'24.10.2024 10:00:00' does not match the format");
    const char *month13[] = {"24/13/2024 10:00:00"};
    CHECK(series(f, NULL, month13, 1, t, &err) == PHC_ERR_INPUT);
    const char *trail[] = {"24/10/2024 10:00:00 x"};
    CHECK(series(f, NULL, trail, 1, t, &err) == PHC_ERR_INPUT);
    CHECK_STR_CONTAINS(err.message, "unexpected 'x'");
    /* ISO: wrong separators, an hour 25, a day-first date, an empty cell */
    const char *iso_bad[] = {"2024/10/24 10:00:00", "2024-10-24 25:00:00", "24/10/2024 10:00:00",
                             "", "2024-10-24T10:00:00+2", "2024-10-24T10:00:00Zulu"};
    for (size_t i = 0; i < sizeof iso_bad / sizeof *iso_bad; ++i) {
        CHECK(series(NULL, NULL, &iso_bad[i], 1, t, &err) == PHC_ERR_INPUT);
        CHECK_STR_CONTAINS(err.message, "does not match the format ISO 8601");
    }
}

static void test_local_clock(void)
{
    phc_error err;
    double s = -1;
    CHECK(phc_local_clock("Europe/Berlin", T_0701_0500, &s, &err) == PHC_OK);
    CHECK_NEAR(s, 7 * H, 0, 0); /* 07:00 CEST */
    CHECK(phc_local_clock(NULL, T_0701_0500 + 0.5, &s, &err) == PHC_OK);
    CHECK_NEAR(s, 5 * H + 0.5, 1e-6, 0);
    CHECK(phc_local_clock("Europe/Berlin", T_0330_0600, &s, &err) == PHC_OK);
    CHECK_NEAR(s, 7 * H, 0, 0); /* 07:00 CET */
    /* the repeated hour reads 02:30 at 00:30 and at 01:30 UTC */
    CHECK(phc_local_clock("Europe/Berlin", T_1027_0000 + 0.5 * H, &s, &err) == PHC_OK);
    CHECK_NEAR(s, 2.5 * H, 0, 0);
    CHECK(phc_local_clock("Europe/Berlin", T_1027_0000 + 1.5 * H, &s, &err) == PHC_OK);
    CHECK_NEAR(s, 2.5 * H, 0, 0);
    /* just before local midnight (21:59:59.5 UTC in summer), and before 1970 */
    CHECK(phc_local_clock("Europe/Berlin", T_0701_0500 + 16 * H + 3599.5, &s, &err) == PHC_OK);
    CHECK_NEAR(s, 86399.5, 1e-6, 0);
    CHECK(phc_local_clock(NULL, -1.0, &s, &err) == PHC_OK);
    CHECK_NEAR(s, 86399, 0, 0);
    CHECK(phc_local_clock(NULL, NAN, &s, &err) == PHC_ERR_INVALID);
    char iso[40];
    CHECK(phc_local_iso("Europe/Berlin", T_1024_1105_07 + 0.9, iso, sizeof iso, &err) == PHC_OK);
    CHECK(strcmp(iso, "2024-10-24T13:05:07+02:00") == 0);
    CHECK(phc_local_iso("America/New_York", T_0330_0600, iso, sizeof iso, &err) == PHC_OK);
    CHECK(strcmp(iso, "2024-03-30T02:00:00-04:00") == 0);
    CHECK(phc_local_iso(NULL, -1.0, iso, sizeof iso, &err) == PHC_OK);
    CHECK(strcmp(iso, "1969-12-31T23:59:59+00:00") == 0);
    double ts[3] = {T_0330_0600, T_0701_0500, T_1027_0000}, out[3];
    CHECK(phc_local_clocks("Europe/Berlin", ts, 3, out, &err) == PHC_OK);
    CHECK_NEAR(out[0], 7 * H, 0, 0);
    CHECK_NEAR(out[1], 7 * H, 0, 0);
    CHECK_NEAR(out[2], 2 * H, 0, 0);
}

static void test_daily_times(void)
{
    phc_error err;
    double *t = NULL;
    size_t n = 0;
    /* 07:00 around the spring change: [03-29 12:00, 04-02 12:00] UTC holds
     * 03-30 06:00 (CET), then 03-31, 04-01, 04-02 at 05:00 UTC (CEST) */
    const double t0 = T_0330_0600 + 6 * H, t1 = t0 + 2 * 86400;
    CHECK(phc_local_daily_times("Europe/Berlin", t0, t1, 7 * H, &t, &n, &err) == PHC_OK);
    CHECK(n == 4);
    if (n == 4) {
        CHECK_NEAR(t[0], T_0330_0600, 0, 0);
        CHECK_NEAR(t[1], T_0331_0100 + 4 * H, 0, 0); /* 2024-03-31 05:00 UTC */
        CHECK_NEAR(t[2], t[1] + 86400, 0, 0);
        CHECK_NEAR(t[3], t[1] + 2 * 86400, 0, 0);
    }
    free(t);
    /* UTC: every day at 07:00 UTC, 3 in [t0 - 1 d, t0 + 1 d] when t0 is 07:00 */
    CHECK(phc_local_daily_times(NULL, T_0330_0600 + H, T_0330_0600 + H, 7 * H, &t, &n, &err) == PHC_OK);
    CHECK(n == 3);
    if (n == 3)
        CHECK_NEAR(t[0], T_0330_0600 + H - 86400, 0, 0);
    free(t);
    /* the autumn change: 07:00 CEST on 10-26 is 05:00 UTC (outside), then
     * 10-27 and 10-28 at 06:00 UTC (CET) */
    CHECK(phc_local_daily_times("Europe/Berlin", T_1027_0000 + 12 * H, T_1027_0000 + 12 * H, 7 * H,
                                &t, &n, &err) == PHC_OK);
    CHECK(n == 2);
    if (n == 2) {
        CHECK_NEAR(t[0], T_1027_0000 + 6 * H, 0, 0);
        CHECK_NEAR(t[1], T_1027_0000 + 30 * H, 0, 0);
    }
    free(t);
    /* 02:30 on the change nights: the first occurrence in autumn, the jump
     * (01:00 UTC) in spring; one time per day either way */
    CHECK(phc_local_daily_times("Europe/Berlin", T_1027_0000, T_1027_0000, 2.5 * H, &t, &n, &err) == PHC_OK);
    CHECK(n == 2);
    if (n == 2) {
        CHECK_NEAR(t[0], T_1027_0000 + 0.5 * H - 86400, 0, 0); /* 10-26 02:30 CEST */
        CHECK_NEAR(t[1], T_1027_0000 + 0.5 * H, 0, 0);         /* 10-27 02:30 CEST */
    }
    free(t);
    CHECK(phc_local_daily_times("Europe/Berlin", T_0331_0100, T_0331_0100, 2.5 * H, &t, &n, &err) == PHC_OK);
    CHECK(n == 3);
    if (n == 3) {
        CHECK_NEAR(t[0], T_0331_0100 - 86400 + 0.5 * H, 0, 0); /* 03-30 02:30 CET = 01:30 UTC */
        CHECK_NEAR(t[1], T_0331_0100, 0, 0);                   /* the jump */
        CHECK_NEAR(t[2], T_0331_0100 + 86400 - 0.5 * H, 0, 0); /* 04-01 02:30 CEST = 00:30 UTC */
    }
    free(t);
    /* sorted and one per day over a year */
    CHECK(phc_local_daily_times("Europe/Berlin", T_0330_0600 - 100 * 86400, T_0330_0600 + 265 * 86400,
                                19.25 * H, &t, &n, &err) == PHC_OK);
    CHECK(n == 367);
    int sorted = 1;
    for (size_t i = 1; i < n; ++i)
        sorted &= t[i] - t[i - 1] >= 23 * H && t[i] - t[i - 1] <= 25 * H;
    CHECK(sorted);
    free(t);
    /* bad arguments */
    CHECK(phc_local_daily_times(NULL, 10, 0, 7 * H, &t, &n, &err) == PHC_ERR_INVALID);
    CHECK(phc_local_daily_times(NULL, 0, 10, 86400, &t, &n, &err) == PHC_ERR_INVALID);
    CHECK(phc_local_daily_times("Nowhere/Town", 0, 10, 0, &t, &n, &err) == PHC_ERR_INPUT);
    CHECK(t == NULL && n == 0);
}

int main(void)
{
    test_iso();
    test_day_first();
    test_spring_forward();
    test_fall_back();
    test_zones();
    test_bad_dates();
    test_local_clock();
    test_daily_times();
    return check_finish("test_logger_time");
}
