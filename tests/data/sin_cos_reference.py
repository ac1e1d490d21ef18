# Writes tests/data/sin_cos_reference.csv: sin and cos of 6,415 doubles, correctly rounded to f64
# (mpmath at 80 significant digits, printed to 40 and parsed by Python's correctly rounded
# float()), the reference of tests/tests/lanes.rs for the lanes' vector sin_cos.
# Run from the repository root: python3 tests/data/sin_cos_reference.py (pip install mpmath).
import mpmath, random, struct
mpmath.mp.dps = 80
random.seed(20261127)
xs = [0.0, -0.0, 5e-324, 1e-300, 1e-8, -1e-8, 0.5, 1.0, 3.0, 1e3, 823549.0, -823549.0]
for r in (1.0, 4.0, 100.0, 1e4, 8.2e5):
    xs += [random.uniform(-r, r) for _ in range(800)]
# Doubles next to multiples of pi/2 (where sin or cos is near zero: the reduction's worst case).
for k in list(range(-40, 41)) + [random.randint(-500000, 500000) for _ in range(400)]:
    t = float(mpmath.mpf(k) * mpmath.pi / 2)
    for d in (-2, -1, 0, 1, 2):
        bits = struct.unpack('<q', struct.pack('<d', t))[0] + d
        x = struct.unpack('<d', struct.pack('<q', bits))[0]
        if abs(x) <= 823549.0:
            xs.append(x)
with open('tests/data/sin_cos_reference.csv', 'w') as f:
    f.write('# x, sin x, cos x: correctly rounded f64 (mpmath 1.3.0, 80 digits; written by tests/data/sin_cos_reference.py)\n')
    for x in xs:
        m = mpmath.mpf(x)
        f.write(f'{x!r},{float(mpmath.nstr(mpmath.sin(m), 40, strip_zeros=False))!r},{float(mpmath.nstr(mpmath.cos(m), 40, strip_zeros=False))!r}\n')
print(len(xs))
