#!/usr/bin/python3
"""The Cornell box from the published data of the Cornell University Program of Computer Graphics
("Cornell Box Data", https://www.graphics.cornell.edu/online/box/data.html): geometry in millimetres
(written in metres, x 0.001), the Lambertian reflectance spectra of its white, green and red surfaces
(400-700 nm every 4 nm) and the light's emission spectrum (400, 500, 600, 700 nm), converted to linear RGB.

Conversion (spectrum -> linear sRGB): XYZ = integral over 400-700 nm (1 nm steps, the spectra interpolated
linearly) of the spectrum times the CIE 1931 2-degree colour-matching functions, taken from the multi-lobe
Gaussian fit of Wyman, Sloan and Shirley (JCGT 2(2), 2013; within about 1% of the CIE tables); scaled so that a
flat spectrum of value 1 has Y = 1; adapted from that flat spectrum's white to D65 by the Bradford transform;
then the XYZ -> linear sRGB (Rec. 709) matrix. A flat spectrum c so becomes (c, c, c): a reflectance keeps its
grey level, and the light's spectral radiance (W/(m^2 sr nm) in the data's own scale) becomes RGB radiance of
the same luminance as a flat spectrum of that level.

The light: the published 130 x 105 mm quad, 0.1 mm below the ceiling (y = 548.7 mm against the ceiling's
548.8 mm) so that it is not coplanar with it, facing down. The camera: (278, 273, -800) mm looking +Z, focal
length 35 mm on a 25 mm film (yfov = 2 atan(12.5 / 35) = 39.31 degrees). Every face is wound to face the
inside of the box (the blocks: away from their own centre); the blocks have no bottom, as in the data.
The left (red) wall's four published corners are not coplanar: it is split along its 0-2 diagonal.
"""
import math

WAVELENGTHS = list(range(400, 701, 4))
# Reflectance at WAVELENGTHS (the data's table "Surface reflectances").
WHITE = [0.343, 0.445, 0.551, 0.624, 0.665, 0.687, 0.708, 0.723, 0.715, 0.710, 0.745, 0.758, 0.739, 0.767, 0.777,
         0.765, 0.751, 0.745, 0.748, 0.729, 0.745, 0.757, 0.753, 0.750, 0.746, 0.747, 0.735, 0.732, 0.739, 0.734,
         0.725, 0.721, 0.733, 0.725, 0.732, 0.743, 0.744, 0.748, 0.728, 0.716, 0.733, 0.726, 0.713, 0.740, 0.754,
         0.764, 0.752, 0.736, 0.734, 0.741, 0.740, 0.732, 0.745, 0.755, 0.751, 0.744, 0.731, 0.733, 0.744, 0.731,
         0.712, 0.708, 0.729, 0.730, 0.727, 0.707, 0.703, 0.729, 0.750, 0.760, 0.751, 0.739, 0.724, 0.730, 0.740,
         0.737]
GREEN = [0.092, 0.096, 0.098, 0.097, 0.098, 0.095, 0.095, 0.097, 0.095, 0.094, 0.097, 0.098, 0.096, 0.101, 0.103,
         0.104, 0.107, 0.109, 0.112, 0.115, 0.125, 0.140, 0.160, 0.187, 0.229, 0.285, 0.343, 0.390, 0.435, 0.464,
         0.472, 0.476, 0.481, 0.462, 0.447, 0.441, 0.426, 0.406, 0.373, 0.347, 0.337, 0.314, 0.285, 0.277, 0.266,
         0.250, 0.230, 0.207, 0.186, 0.171, 0.160, 0.148, 0.141, 0.136, 0.130, 0.126, 0.123, 0.121, 0.122, 0.119,
         0.114, 0.115, 0.117, 0.117, 0.118, 0.120, 0.122, 0.128, 0.132, 0.139, 0.144, 0.146, 0.150, 0.152, 0.157,
         0.159]
RED = [0.040, 0.046, 0.048, 0.053, 0.049, 0.050, 0.053, 0.055, 0.057, 0.056, 0.059, 0.057, 0.061, 0.061, 0.060,
       0.062, 0.062, 0.062, 0.061, 0.062, 0.060, 0.059, 0.057, 0.058, 0.058, 0.058, 0.056, 0.055, 0.056, 0.059,
       0.057, 0.055, 0.059, 0.059, 0.058, 0.059, 0.061, 0.061, 0.063, 0.063, 0.067, 0.068, 0.072, 0.080, 0.090,
       0.099, 0.124, 0.154, 0.192, 0.255, 0.287, 0.349, 0.402, 0.443, 0.487, 0.513, 0.558, 0.584, 0.620, 0.606,
       0.609, 0.651, 0.612, 0.610, 0.650, 0.638, 0.627, 0.620, 0.630, 0.628, 0.642, 0.639, 0.657, 0.639, 0.635,
       0.642]
LIGHT_WAVELENGTHS = [400, 500, 600, 700]
LIGHT = [0.0, 8.0, 15.6, 18.4]  # the data's "Light" emission spectrum

MM = 0.001
LIGHT_Y = 548.7  # mm; the ceiling is at 548.8
INSIDE = (278.0, 274.4, 279.6)  # a point inside the box (mm), which every wall faces
WALLS = [  # (name, material, corners in mm) as published
    ("floor", "white", [(552.8, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 559.2), (549.6, 0.0, 559.2)]),
    ("ceiling", "white", [(556.0, 548.8, 0.0), (556.0, 548.8, 559.2), (0.0, 548.8, 559.2), (0.0, 548.8, 0.0)]),
    ("back_wall", "white", [(549.6, 0.0, 559.2), (0.0, 0.0, 559.2), (0.0, 548.8, 559.2), (556.0, 548.8, 559.2)]),
    ("right_wall_green", "green", [(0.0, 0.0, 559.2), (0.0, 0.0, 0.0), (0.0, 548.8, 0.0), (0.0, 548.8, 559.2)]),
    ("left_wall_red", "red", [(552.8, 0.0, 0.0), (549.6, 0.0, 559.2), (556.0, 548.8, 559.2), (556.0, 548.8, 0.0)]),
]
BLOCK_TOPS = [  # (name, top corners in mm); the sides run down to the floor
    ("short_block", [(130.0, 165.0, 65.0), (82.0, 165.0, 225.0), (240.0, 165.0, 272.0), (290.0, 165.0, 114.0)]),
    ("tall_block", [(423.0, 330.0, 247.0), (265.0, 330.0, 296.0), (314.0, 330.0, 456.0), (472.0, 330.0, 406.0)]),
]
LIGHT_QUAD = [(343.0, LIGHT_Y, 227.0), (343.0, LIGHT_Y, 332.0), (213.0, LIGHT_Y, 332.0), (213.0, LIGHT_Y, 227.0)]
CAMERA_EYE, CAMERA_TARGET = (278.0, 273.0, -800.0), (278.0, 273.0, 0.0)
CAMERA_YFOV = math.degrees(2.0 * math.atan(12.5 / 35.0))

BRADFORD = [[0.8951, 0.2664, -0.1614], [-0.7502, 1.7135, 0.0367], [0.0389, -0.0685, 1.0296]]
BRADFORD_INV = [[0.9869929, -0.1470543, 0.1599627], [0.4323053, 0.5183603, 0.0492912],
                [-0.0085287, 0.0400428, 0.9684867]]
D65 = (0.95047, 1.0, 1.08883)
XYZ_TO_SRGB = [[3.2404542, -1.5371385, -0.4985314], [-0.9692660, 1.8760108, 0.0415560],
               [0.0556434, -0.2040259, 1.0572252]]


def _lobe(lam, mu, s1, s2):
    t = (lam - mu) / (s1 if lam < mu else s2)
    return math.exp(-0.5 * t * t)


def cmf(lam):
    """CIE 1931 2-degree x, y, z bar at lam nm (Wyman, Sloan and Shirley's multi-lobe fit)."""
    x = 1.056 * _lobe(lam, 599.8, 37.9, 31.0) + 0.362 * _lobe(lam, 442.0, 16.0, 26.7) - 0.065 * _lobe(lam, 501.1, 20.4, 26.2)
    y = 0.821 * _lobe(lam, 568.8, 46.9, 40.5) + 0.286 * _lobe(lam, 530.9, 16.3, 31.1)
    z = 1.217 * _lobe(lam, 437.0, 11.8, 36.0) + 0.681 * _lobe(lam, 459.0, 26.0, 13.8)
    return x, y, z


def _interp(xs, ys, x):
    for i in range(len(xs) - 1):
        if xs[i] <= x <= xs[i + 1]:
            t = (x - xs[i]) / (xs[i + 1] - xs[i])
            return ys[i] + t * (ys[i + 1] - ys[i])
    raise ValueError("%g nm outside %g-%g nm" % (x, xs[0], xs[-1]))


def _mul(m, v):
    return [sum(m[r][c] * v[c] for c in range(3)) for r in range(3)]


def _xyz(wavelengths, values):
    s = [0.0, 0.0, 0.0]
    for lam in range(400, 701):
        f = _interp(wavelengths, values, lam)
        for k, c in enumerate(cmf(lam)):
            s[k] += f * c
    return s


def spectrum_to_rgb(wavelengths, values):
    """Linear sRGB of a reflectance or radiance spectrum (a flat spectrum c gives (c, c, c))."""
    white = _xyz([400, 700], [1.0, 1.0])
    xyz = [v / white[1] for v in _xyz(wavelengths, values)]
    lw, ld = _mul(BRADFORD, [w / white[1] for w in white]), _mul(BRADFORD, D65)
    lms = _mul(BRADFORD, xyz)
    adapted = _mul(BRADFORD_INV, [lms[k] * ld[k] / lw[k] for k in range(3)])
    return [round(c, 5) for c in _mul(XYZ_TO_SRGB, adapted)]


def _sub(a, b):
    return tuple(x - y for x, y in zip(a, b))


def _facing(corners, toward, inward=True):
    """corners wound so the normal of their first triangle points at `toward` (away from it if not inward)."""
    n = _cross(_sub(corners[1], corners[0]), _sub(corners[2], corners[0]))
    d = sum(a * b for a, b in zip(n, _sub(toward, corners[0])))
    return list(corners) if (d > 0) == inward else list(reversed(corners))


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _metres(poly):
    return [tuple(c * MM for c in p) for p in poly]


def scene_parts():
    """[(name, material name, polygons in metres)], materials {name: (base colour, emission)}."""
    parts = [(name, mat, [_metres(_facing(c, INSIDE))]) for name, mat, c in WALLS]
    for name, top in BLOCK_TOPS:
        centre = (sum(p[0] for p in top) / 4, top[0][1] / 2, sum(p[2] for p in top) / 4)
        polys = [_facing(top, centre, inward=False)]
        for i in range(4):
            t0, t1 = top[i], top[(i + 1) % 4]
            polys.append(_facing([(t0[0], 0.0, t0[2]), t0, t1, (t1[0], 0.0, t1[2])], centre, inward=False))
        parts.append((name, "white", [_metres(p) for p in polys]))
    parts.append(("light", "light", [_metres(_facing(LIGHT_QUAD, (278.0, 0.0, 279.6)))]))
    white = spectrum_to_rgb(WAVELENGTHS, WHITE)
    materials = {"white": (white, (0, 0, 0)), "green": (spectrum_to_rgb(WAVELENGTHS, GREEN), (0, 0, 0)),
                 "red": (spectrum_to_rgb(WAVELENGTHS, RED), (0, 0, 0)),
                 # The light's own reflectance is not published: the white's.
                 "light": (white, spectrum_to_rgb(LIGHT_WAVELENGTHS, LIGHT))}
    return parts, materials


def camera():
    return tuple(c * MM for c in CAMERA_EYE), tuple(c * MM for c in CAMERA_TARGET), CAMERA_YFOV


if __name__ == "__main__":
    _, mats = scene_parts()
    for k, (rho, le) in mats.items():
        print("%-6s base colour %s emission %s" % (k, rho, le))
    print("flat 1 ->", spectrum_to_rgb([400, 700], [1.0, 1.0]))
