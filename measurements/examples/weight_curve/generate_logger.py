#!/usr/bin/env python3
"""Generates logger_ivy.csv: a balance logger's file of a detached ivy leaf
drying (SYNTHETIC, project-authored), for logger.yaml.

The file looks like what a lab balance's data logger writes: a date and a time
in two columns, day-first (25/10/2024), in the local clock of Europe/Berlin,
which steps back from 03:00 CEST to 02:00 CET on 2024-10-27 (the hour from
02:00 to 02:59 appears twice); a mass column in g and a status column (ST
stable, US unstable).  On top of the leaf's curve it has:
  - a tare reading: the empty balance (0.0003 g) just before the leaf is put on;
  - unstable readings (3%, seeded): the balance was disturbed (a draught, the
    door), the mass is off by up to +-20 mg and the status is US;
  - a gap: the logger was off from 2024-10-26 02:10 to 09:40 local (7.5 h).
Readings every 10 minutes from 2024-10-25 16:00 CEST to 2024-10-28 10:00 CET.

The leaf's water follows the wilting paper's water model in its fast-mixing
limit (pressure equalises along the veins much faster than the leaf loses
water, so the whole leaf decays as one exponential):
    mass(t) = dry + W0 exp(-delta * Abar * t)
where Abar is the volume-weighted leaf area proxy of phytocal's detached-leaf
chain (model/plant_graph.c, phc_plant_graph_leaf_chain): `chain_segments`
equal segments of radius r along a midrib of length L = sqrt(2 * leaf_area),
all but the first (the petiole) leaf segments, A_i = r h (cm2), so
Abar = (N - 1) / N * r * h.  This is independent of phytocal's evaluators
(closed form here, eigen or BDF6 there).  True values: delta = 4.0e-4
s-1 cm-2, W0 = 1.20 g, dry mass 0.42 g, leaf area 40 cm2, 20 segments,
vein radius 0.5 mm; balance noise sd 0.5 mg (seed 20241027).

Local times come from Python's zoneinfo over the system tzdata, not from
phytocal.  Run with Debian's system python3 (standard library only):
    /usr/bin/python3 measurements/examples/weight_curve/generate_logger.py
The file it writes is committed; re-running reproduces it exactly.
"""
import datetime as dt
import math
import os
import random
from zoneinfo import ZoneInfo

HERE = os.path.dirname(os.path.abspath(__file__))
ZONE = ZoneInfo('Europe/Berlin')

DELTA = 4.0e-4          # s-1 cm-2
W0 = 1.20               # g, water at the first weighing of the leaf
DRY = 0.42              # g
AREA_CM2 = 40.0
SEGMENTS = 20
RADIUS_CM = 0.05
NOISE_SD = 0.0005       # g
STEP = dt.timedelta(minutes=10)


def abar():
    length_cm = math.sqrt(2.0 * AREA_CM2 * 1e-4) * 100.0   # midrib length
    h = length_cm / SEGMENTS
    return (SEGMENTS - 1) / SEGMENTS * RADIUS_CM * h


def main():
    rng = random.Random(20241027)
    start = dt.datetime(2024, 10, 25, 16, 0, tzinfo=ZONE).astimezone(dt.timezone.utc)
    end = dt.datetime(2024, 10, 28, 10, 0, tzinfo=ZONE).astimezone(dt.timezone.utc)
    off_from = dt.datetime(2024, 10, 26, 2, 10, tzinfo=ZONE).astimezone(dt.timezone.utc)
    off_to = dt.datetime(2024, 10, 26, 9, 40, tzinfo=ZONE).astimezone(dt.timezone.utc)
    rate = DELTA * abar()                                  # s-1
    rows = []
    tare_time = start - dt.timedelta(seconds=90)
    rows.append((tare_time, 0.0003, 'ST'))
    t = start
    while t <= end:
        if not (off_from < t < off_to):
            sec = (t - start).total_seconds()
            m = DRY + W0 * math.exp(-rate * sec) + rng.gauss(0.0, NOISE_SD)
            status = 'ST'
            if rng.random() < 0.03:
                m += rng.uniform(-0.020, 0.020)
                status = 'US'
            rows.append((t, m, status))
        t += STEP
    with open(os.path.join(HERE, 'logger_ivy.csv'), 'w') as f:
        f.write('# SYNTHETIC balance-logger file of a detached ivy leaf, made by generate_logger.py:\n')
        f.write('# fast-mixing limit of the wilting-paper water model, delta = %g s-1 cm-2, water %g g,\n'
                % (DELTA, W0))
        f.write('# dry mass %g g, leaf area %g cm2; local time Europe/Berlin (DST ends 27/10/2024 03:00);\n'
                % (DRY, AREA_CM2))
        f.write('# a tare line, unstable (US) readings, the logger off 26/10 02:10-09:40\n')
        f.write('Date,Time,Weight,Status\n')
        for t, m, s in rows:
            local = t.astimezone(ZONE)
            f.write('%s,%s,%.4f,%s\n' % (local.strftime('%d/%m/%Y'), local.strftime('%H:%M:%S'), m, s))
    print('wrote logger_ivy.csv: %d rows (%d unstable); Abar = %.6g cm2, half-life %.3g h'
          % (len(rows), sum(r[2] == 'US' for r in rows), abar(), math.log(2) / rate / 3600))


if __name__ == '__main__':
    main()
