"""A 3-D colour lookup table: a real .cube file written, parsed back, and applied with trilinear filtering.

    python examples/textures/lut.py [--out DIR] [--size 512] [--repeat 5]

The grade: a warm white balance (x1.08 red, x0.84 blue), a filmic contrast (a power of 1.3 about
middle grey, then an extended-Reinhard shoulder that maps the new white to 1) and +10% saturation,
all on **linear-light** Rec.709/sRGB values in [0, 1]. ``write_cube`` samples it on a 33^3 grid and
writes the Adobe/Resolve ``.cube`` text format (``TITLE``, ``DOMAIN_MIN``/``DOMAIN_MAX``,
``LUT_3D_SIZE 33``, then 35,937 lines ``r g b`` with red changing fastest) to the output directory;
``parse_cube`` reads it back as any user's LUT would be read (comments, keywords, the domain and the
count checked) into a (B, G, R, 3) float32 array: exactly the (z, y, x, channels) layout a
``Texture3D[vec3, "clamp", "linear"]`` takes, so red is the texture's x.

The kernel takes the photograph (matplotlib's Grace Hopper, (H, W, 3) uint8: a ``u8vec3``
operand, the array's last axis) and the LUT, decodes each channel with the exact
``srgb8_decode`` (a table read), samples the LUT with its node k at the texel centre
``(k + 0.5) / N``: ``u' = (u (N - 1) + 0.5) / N``, N read from ``lut.size`` (so the kernel takes a
LUT of any size), and encodes the graded linear colour with ``srgb8_encode`` into a ``u8vec4``:
the PNG is the (H, W, 4) uint8 array the kernel returns. The grading is in linear light (decode,
LUT, encode), which is how a scene-referred grade is applied; the price of a linear-domain LUT is
that its 33 nodes are sparse in the shadows (node 1 is at 1/32 = code 50): the report gives the
LUT's own error against the analytic grade beside the kernel's error against the LUT.

The NumPy reference decodes with the sRGB formula in float64, interpolates the same LUT with
the textbook trilinear formula (position ``x (N - 1)``, no texel centres), and encodes in float64;
the same code on float32 arrays is the NumPy float32 figure.
"""
from __future__ import annotations

import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from textures_common import (  # noqa: E402
    best_time, code_lines, compare, format_report, load_photo, numpy_codes_f32, reference_codes, scene_main,
    srgb_decode64, timed_build, with_alpha,
)

import reactor  # noqa: E402
from reactor import Float, Texture3D, u8vec3, u8vec4, vec3  # noqa: E402
from routines.pixels import srgb8_decode, srgb8_encode  # noqa: E402

LUT_SIZE = 33
TITLE = "reactor warm filmic"
WARM = (1.08, 1.0, 0.84)
CONTRAST = 1.3
SATURATION = 1.1
LUMA = (0.2126, 0.7152, 0.0722)


def grade(rgb: np.ndarray) -> np.ndarray:
    """The analytic grade on linear RGB (..., 3) in float64: what the LUT tabulates."""
    c = np.asarray(rgb, np.float64) * np.array(WARM)
    c = 0.18 * (c / 0.18) ** CONTRAST                       # contrast about middle grey
    white = 0.18 * (max(WARM) / 0.18) ** CONTRAST           # where the warmest white lands
    c = c * (1.0 + c / white ** 2) / (1.0 + c)              # a shoulder mapping it to 1
    luma = (c * np.array(LUMA)).sum(-1, keepdims=True)
    return np.clip(luma + SATURATION * (c - luma), 0.0, 1.0)


def write_cube(path: str, size: int = LUT_SIZE, title: str = TITLE) -> None:
    """The grade sampled on a size^3 grid as an Adobe/Resolve .cube file (red fastest)."""
    grid = np.linspace(0.0, 1.0, size)
    b, g, r = np.meshgrid(grid, grid, grid, indexing="ij")          # [b, g, r]: r varies fastest
    values = grade(np.stack([r, g, b], -1)).reshape(-1, 3)
    with open(path, "w", encoding="ascii", newline="\n") as f:
        f.write(f'# {title}: warm balance, filmic contrast, saturation; linear-light input and output\n')
        f.write(f'TITLE "{title}"\n')
        f.write("DOMAIN_MIN 0.0 0.0 0.0\nDOMAIN_MAX 1.0 1.0 1.0\n")
        f.write(f"LUT_3D_SIZE {size}\n\n")
        f.writelines(f"{v[0]:.6f} {v[1]:.6f} {v[2]:.6f}\n" for v in values)


def parse_cube(path: str):
    """Read a 3-D .cube LUT: ``(title, table)`` with ``table[b, g, r] = (R, G, B)`` as float32.
    Handles comments, blank lines, TITLE, DOMAIN_MIN/MAX (only the default [0, 1] domain: this
    example applies no input scaling) and LUT_3D_SIZE; a 1-D LUT is refused."""
    title, size, rows = None, None, []
    domain = {"DOMAIN_MIN": [0.0] * 3, "DOMAIN_MAX": [1.0] * 3}
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            line = line.split("#", 1)[0].strip()
            if not line:
                continue
            key, _, rest = line.partition(" ")
            if key == "TITLE":
                title = rest.strip().strip('"')
            elif key == "LUT_3D_SIZE":
                size = int(rest)
                if not 2 <= size <= 256:
                    raise ValueError(f"{path}:{number}: LUT_3D_SIZE {size} out of range (2..256)")
            elif key == "LUT_1D_SIZE":
                raise ValueError(f"{path}:{number}: a 1-D LUT; this reader takes 3-D LUTs")
            elif key in domain:
                domain[key] = [float(v) for v in rest.split()]
            elif key[0].isdigit() or key[0] in "+-.":
                row = [float(v) for v in line.split()]
                if len(row) != 3:
                    raise ValueError(f"{path}:{number}: a data line has 3 values, not {len(row)}")
                rows.append(row)
            else:
                raise ValueError(f"{path}:{number}: unknown keyword {key!r}")
    if size is None:
        raise ValueError(f"{path}: no LUT_3D_SIZE")
    if domain != {"DOMAIN_MIN": [0.0] * 3, "DOMAIN_MAX": [1.0] * 3}:
        raise ValueError(f"{path}: domain {domain} (this example takes the default [0, 1])")
    if len(rows) != size ** 3:
        raise ValueError(f"{path}: {len(rows)} data lines for LUT_3D_SIZE {size} ({size ** 3} expected)")
    return title, np.array(rows, np.float32).reshape(size, size, size, 3)


# --- DSL begin
def graded(c, lut):
    """The graded linear colour of an sRGB8 pixel: exact decode, trilinear LUT lookup."""
    linear = vec3(srgb8_decode(c.r), srgb8_decode(c.g), srgb8_decode(c.b))
    n = vec3(*(Float(s) for s in lut.size))              # LUT size per axis (x = red first)
    uvw = (linear * (n - 1.0) + 0.5) / n                 # node k at the texel centre (k + 0.5) / N
    return lut.sample(uvw)


def lut_rgba8(c: u8vec3, lut: Texture3D[vec3, "clamp", "linear"]) -> u8vec4:
    g = graded(c, lut)
    return u8vec4(srgb8_encode(g.r), srgb8_encode(g.g), srgb8_encode(g.b), 255)


def lut_linear(c: u8vec3, lut: Texture3D[vec3, "clamp", "linear"]) -> vec3:
    return graded(c, lut)
# --- DSL end


def build(body):
    return reactor.kernel(body, cache=False)


# --- NumPy begin
def np_trilinear(rgb, table):
    """Trilinear interpolation of ``table[b, g, r]`` at ``rgb`` (..., 3) in [0, 1], in rgb's dtype."""
    F = rgb.dtype.type
    n = table.shape[0]
    p = np.clip(rgb, F(0), F(1)) * F(n - 1)                  # node coordinates
    i = np.minimum(np.floor(p).astype(np.int64), n - 2)
    f = p - i.astype(F)
    t = table.astype(F)
    out = np.zeros(rgb.shape, F)
    for corner in range(8):
        dr, dg, db = corner & 1, (corner >> 1) & 1, (corner >> 2) & 1
        weight = ((f[..., 0] if dr else F(1) - f[..., 0]) * (f[..., 1] if dg else F(1) - f[..., 1])
                  * (f[..., 2] if db else F(1) - f[..., 2]))
        out += weight[..., None] * t[i[..., 2] + db, i[..., 1] + dg, i[..., 0] + dr]
    return out


def np_decode(codes, dtype):
    y = codes.astype(dtype) / dtype(255)
    return np.where(y <= dtype(0.04045), y / dtype(12.92), ((y + dtype(0.055)) / dtype(1.055)) ** dtype(2.4))
# --- NumPy end


def numpy_rgba8(photo, table):
    """The NumPy float32 pipeline, through to RGBA8 codes (what is timed against the kernel)."""
    return with_alpha(numpy_codes_f32(np_trilinear(np_decode(photo, np.float32), table)))


def run(size: int = 512, repeat: int = 5, cube_dir: str | None = None) -> dict:
    photo = load_photo(size)
    cube = os.path.join(cube_dir or ".", "warm_filmic.cube")
    write_cube(cube)
    title, table = parse_cube(cube)
    rgba8, build_u8 = timed_build(build, lut_rgba8)
    linear, build_f = timed_build(build, lut_linear)

    image = rgba8(photo, table)
    lin = linear(photo, table)
    ref_lin = np_trilinear(srgb_decode64(photo), table.astype(np.float64))
    ref = reference_codes(ref_lin)
    np_lin = np_trilinear(np_decode(photo, np.float32), table)
    np_image = numpy_rgba8(photo, table)
    accuracy = {"reactor": compare(image, ref, lin, ref_lin), "numpy_f32": compare(np_image, ref, np_lin, ref_lin)}
    ms = {"reactor": best_time(rgba8, photo, table, repeat=repeat),
          "numpy_f32": best_time(numpy_rgba8, photo, table, repeat=repeat)}
    exact = reference_codes(grade(srgb_decode64(photo)))      # the analytic grade, no LUT
    lut_error = compare(ref, exact)
    return {
        "scene": "lut", "shape": image.shape, "rgba": image, "accuracy": accuracy, "ms": ms,
        "build_ms": {"rgba8": build_u8, "linear": build_f},
        "lines": {"dsl": code_lines(__file__, "DSL"), "numpy": code_lines(__file__, "NumPy")},
        "u8_vs_linear_kernel": int(np.count_nonzero(image[..., :3] != reference_codes(lin))),
        "cube": {"path": cube, "title": title, "size": int(table.shape[0]), "bytes": os.path.getsize(cube)},
        "lut_vs_analytic": lut_error,
        "changed_codes": int(np.count_nonzero(image[..., :3] != photo)),
    }


def report(r: dict) -> str:
    h, w, _ = r["shape"]
    text = format_report(f"3-D LUT ({r['cube']['size']}^3 .cube, trilinear Texture3D) on a {w} x {h} photograph "
                         "in linear light; 8-bit codes against float64:", r)
    e = r["lut_vs_analytic"]
    return (text + f"\n  {r['cube']['path']}: {r['cube']['bytes']:,} bytes, TITLE {r['cube']['title']!r}; the LUT "
            f"itself against the analytic grade (float64): {e['codes_differing']:,} codes differ, "
            f"{e['codes_over_1']:,} by more than 1, max {e['max_code_diff']}\n  u8 kernel vs exact encode of the "
            f"linear kernel: {r['u8_vs_linear_kernel']} codes differ")


def main(argv=None) -> dict:
    from shader_common import parse
    from textures_common import DEFAULT_OUT

    args = parse(argv, __doc__, 512, DEFAULT_OUT)

    def run_here(size, repeat):
        os.makedirs(args.out, exist_ok=True)
        return run(size=size, repeat=repeat, cube_dir=args.out)
    return scene_main(argv, __doc__, "lut", run_here, report)


if __name__ == "__main__":
    main()
