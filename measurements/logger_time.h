/* Timestamps of data loggers (balance loggers, climate loggers) as POSIX
 * seconds, and the local clock of a time zone.
 *
 * A logger writes its readings' times as text in its own local clock: a date
 * and a time, often in two columns, often day-first (24/10/2024 13:05:00),
 * and the clock steps back an hour when daylight saving ends, so one local
 * time can occur twice.  These functions parse such text with a strptime(3)
 * format and convert it to POSIX seconds through a named IANA time zone read
 * from the system's time-zone database (Debian's tzdata:
 * /usr/share/zoneinfo, or $TZDIR when set).
 *
 * Times and clocks: POSIX seconds (s since 1970-01-01T00:00:00Z, leap seconds
 * not counted) as doubles, so fractions of a second are kept; seconds of the
 * local day in [0, 86400).
 *
 * Zones: `tz` is an IANA name ("Europe/Berlin", "America/New_York", "UTC");
 * NULL means UTC (times taken as written).  A name that is not a zone file
 * of the database (or contains "..", or starts with '/') is PHC_ERR_INPUT.
 *
 * Not thread-safe: glibc has no per-call time-zone API, so a conversion
 * through a zone sets the TZ environment variable for its duration (setenv +
 * tzset + localtime_r) and restores it afterwards.  Do not call these while
 * another thread reads the environment or converts local times. */
#ifndef PHC_LOGGER_TIME_H
#define PHC_LOGGER_TIME_H

#include <stddef.h>

#include "model/status.h"

/* PHC_OK when `tz` names a zone file of the time-zone database, else
 * PHC_ERR_INPUT with a message without a location (callers put the config
 * file, line and key before it with phc_error_prefix):
 *     "time zone 'Europe/Berln' is not in /usr/share/zoneinfo (expected an
 *      IANA name such as Europe/Berlin or UTC)"
 * tz NULL is PHC_OK (UTC). */
int phc_time_zone_check(const char *tz, phc_error *err);

/* How one series of logger timestamps is written. */
typedef struct phc_logger_clock {
    const char *format;   /* strptime(3) format of the text, e.g. "%d/%m/%Y %H:%M:%S";
                             NULL or "" = ISO 8601: "YYYY-MM-DDTHH:MM:SS" or
                             "YYYY-MM-DD HH:MM:SS" (seconds optional), optional
                             fraction ".sss", optional "Z" or "+HH:MM"/"-HH:MM"
                             (also "+HHMM", "+HH") */
    const char *timezone; /* IANA zone of the logger's clock, or NULL: times as
                             written, taken as UTC */
    const char *source;   /* the data file, for messages */
    const char *what;     /* the cells, for messages: "column 'Stamp'" or
                             "columns 'Date' and 'Time'" */
} phc_logger_clock;

/* Converts n timestamps text[i], read at file lines lines[i] (1-based), to
 * POSIX seconds t[i].  With a custom format, a fraction of a second after a
 * final %S or %T is accepted ("13:05:07.25"), and %z gives an explicit
 * offset.  A time with an explicit offset (Z, +02:00) is exact whatever the
 * zone.
 *
 * The series must not go back in time (equal times are allowed).  A local
 * time that occurs twice in the zone (the hour repeated when clocks go back)
 * takes the earliest of its instants that is not before the previous
 * reading: 02:30 after 02:50 CEST is 02:30 CET.  The first reading takes the
 * earlier instant.
 *
 * Errors (PHC_ERR_INPUT), each naming source:line:
 *   text not matching the format (also a day that does not exist, 31/02):
 *     "log.csv:17: columns 'Date' and 'Time': '31/02/2024 10:00:00' does not
 *      match the format '%d/%m/%Y %H:%M:%S' (day 31 of month 2 does not exist)"
 *   a local time the zone skips (clocks went forward):
 *     "log.csv:40: column 'Stamp': 2024-03-31 02:30:00 does not exist in
 *      Europe/Berlin (the clocks went forward an hour)"
 *   without a zone, a backward step of up to an hour:
 *     "log.csv:260: columns 'Date' and 'Time': '27/10/2024 02:00:00' is 50 min
 *      before the previous reading (line 259): the clock stepped back, which
 *      looks like the end of daylight saving; set `timezone:` to the
 *      logger's zone (e.g. Europe/Berlin)"
 *   any other backward step: "... is 3.5 h before the previous reading
 *      (line 12); readings must be in time order"
 *   an unknown zone: phc_time_zone_check's message. */
int phc_logger_times(const phc_logger_clock *clock, const char *const *text,
                     const size_t *lines, size_t n, double *t, phc_error *err);

/* The local clock of zone tz (NULL = UTC) at POSIX time t_posix: seconds
 * since local midnight, in [0, 86400) (a day of 23 or 25 h still restarts
 * at local midnight).  PHC_ERR_INPUT for an unknown zone, PHC_ERR_INVALID for
 * a time that is not finite or outside the years 1..9999. */
int phc_local_clock(const char *tz, double t_posix, double *seconds_since_local_midnight,
                    phc_error *err);

/* The same for n times at once (one zone switch for all): seconds[i]. */
int phc_local_clocks(const char *tz, const double *t_posix, size_t n, double *seconds,
                     phc_error *err);

/* Writes t_posix as the local time of zone tz (NULL = UTC) in ISO 8601 with
 * its offset, "2024-10-25T16:00:00+02:00" (whole seconds, rounded down),
 * into buf (at least 26 bytes).  Errors as phc_local_clock. */
int phc_local_iso(const char *tz, double t_posix, char *buf, size_t size, phc_error *err);

/* The POSIX times at which the local clock of zone tz (NULL = UTC) reads
 * `seconds_of_day` (in [0, 86400)), one per local day, for every such time
 * within [t0 - 86400, t1 + 86400], sorted; *times is malloc'd (the caller
 * frees it; NULL when *n is 0).  Daylight saving is the zone's: 07:00 in
 * Europe/Berlin is 06:00 UTC in winter and 05:00 UTC in summer.
 * One time per local day: on the day the clocks go back, a clock time in the
 * repeated hour gives its first occurrence; on the day they go forward, a
 * clock time in the skipped hour gives the instant the clock jumps past it
 * (02:30 on 2024-03-31 in Europe/Berlin: 01:00 UTC, when 02:00 CET became
 * 03:00 CEST).
 * PHC_ERR_INPUT for an unknown zone; PHC_ERR_INVALID when t0 > t1, a time is
 * not finite or seconds_of_day is outside [0, 86400); PHC_ERR_NOMEM. */
int phc_local_daily_times(const char *tz, double t0, double t1, double seconds_of_day,
                          double **times, size_t *n, phc_error *err);

#endif /* PHC_LOGGER_TIME_H */
