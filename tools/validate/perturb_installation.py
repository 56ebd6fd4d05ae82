#!/usr/bin/env python3
"""Another cabin for the several-sensors chain (issue 20): perturb the SGL-like
installation of a scenario file written by `aeromag simulate ... --print-config`
or next to a simulated flight. Current loops are moved (±0.6 m), re-oriented,
resized (×0.5–2), their lags and switching rates changed (×0.6–1.5,
×0.6–1.6); the cabin scalar sensors are moved (±0.4 m). The same SEED gives
the same aircraft in a calibration and a survey file (only their switching
rates differ, as the simulator's calibration cycles the loads).

    python3 tools/validate/perturb_installation.py cal/calibration.toml cal_b.toml 11
    python3 tools/validate/perturb_installation.py survey/survey.toml survey_b.toml 11
    aeromag simulate calibration --config cal_b.toml --seed 5 --out cal_b
    aeromag simulate survey --config survey_b.toml --seed 6 --out survey_b
    aeromag calibrate -i cal_b/calibration.csv --mag mag_1_uc,...,mag_5_uc --vector flux_a \
        --extra <currents> --reference-sensor mag_1_uc --magnitude exact --model m.json
    python3 tools/validate/sensors_against_oracle.py m.json survey_b/survey.csv
"""
import re, sys, random
src, dst, seed = sys.argv[1], sys.argv[2], int(sys.argv[3])
rng = random.Random(seed)
text = open(src).read()
blocks = re.split(r'(?m)^(?=\[)', text)
out = []
cur = None
for b in blocks:
    head = b.split('\n', 1)[0]
    if head.startswith('[[aircraft.currents]]'):
        cur = 'current'
        def pos(m):
            v = [float(x) for x in m.group(1).split(',')]
            v = [x + rng.uniform(-0.6, 0.6) for x in v]
            return 'position_m = [' + ', '.join(f'{x:.3f}' for x in v) + ']'
        b = re.sub(r'position_m = \[([^\]]*)\]', pos, b)
        def nrm(m):
            v = [float(x) + rng.uniform(-0.7, 0.7) for x in m.group(1).split(',')]
            return 'normal = [' + ', '.join(f'{x:.3f}' for x in v) + ']'
        b = re.sub(r'normal = \[([^\]]*)\]', nrm, b)
        b = re.sub(r'area_m2 = ([0-9.e-]+)', lambda m: f'area_m2 = {float(m.group(1)) * rng.uniform(0.5, 2.0):.4f}', b)
        def lag(m):
            v = float(m.group(1))
            return f'field_lag_s = {v * rng.uniform(0.6, 1.5):.3f}' if v > 0 else m.group(0)
        b = re.sub(r'field_lag_s = ([0-9.e-]+)', lag, b)
        f = rng.uniform(0.6, 1.6)
        b = re.sub(r'switches_per_hour = ([0-9.e-]+)', lambda m: f'switches_per_hour = {float(m.group(1)) * f:.3f}', b)
    elif head.startswith('[aircraft.currents.pattern]'):
        f = rng.uniform(0.6, 1.6)
        b = re.sub(r'(changes|runs|cycles|pulses)_per_hour = ([0-9.e-]+)', lambda m: f'{m.group(1)}_per_hour = {float(m.group(2)) * f:.3f}', b)
    elif head.startswith('[[extra_scalars]]'):
        def pos(m):
            v = [float(x) + rng.uniform(-0.4, 0.4) for x in m.group(1).split(',')]
            return 'position_m = [' + ', '.join(f'{x:.3f}' for x in v) + ']'
        b = re.sub(r'position_m = \[([^\]]*)\]', pos, b)
    out.append(b)
open(dst, 'w').write(''.join(out))
