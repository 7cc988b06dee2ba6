"""Re-create this corpus from the package registries: each shader file is taken verbatim from a
pinned release on npm or PyPI (three.js's post-processing shaders are the text of their
``fragmentShader`` template string), with its package's licence beside it. Run it to check that
the files here are what the registries hold:

    python examples/glsl/corpus/fetch.py          # rewrite the files
    python examples/glsl/corpus/fetch.py --check  # exit 1 where a file differs
"""
import argparse
import io
import json
import pathlib
import re
import sys
import tarfile
import urllib.request

HERE = pathlib.Path(__file__).resolve().parent

NPM = "https://registry.npmjs.org/{name}/-/{base}-{version}.tgz"
PYPI = "https://pypi.org/simple/{name}/"  # the simple index (JSON) names the sdist's URL

THREE_SHADERS = ["ACESFilmicToneMappingShader", "ColorCorrectionShader", "DotScreenShader",
                 "HueSaturationShader", "SepiaShader", "SobelOperatorShader", "TechnicolorShader",
                 "VignetteShader"]

#: three.js's shader chunks (``#include <name>`` in its shaders): each is a module's default export
THREE_CHUNKS = ["tonemapping_pars_fragment", "colorspace_pars_fragment"]

#: folder -> (registry, package, version, {file here: path in the archive (a three.js shader: its .js)})
SOURCES = {
    "three.js": ("npm", "three", "0.187.0", {
        "LICENSE": "package/LICENSE",
        **{f"{n}.frag": f"package/examples/jsm/shaders/{n}.js" for n in THREE_SHADERS},
        **{f"{n}.glsl": f"package/src/renderers/shaders/ShaderChunk/{n}.glsl.js" for n in THREE_CHUNKS}}),
    "glsl-atmosphere": ("npm", "glsl-atmosphere", "2.0.0", {
        "LICENSE": "package/LICENSE", "index.glsl": "package/index.glsl",
        "example/example.frag": "package/example/example.frag", "example/example.vert": "package/example/example.vert"}),
    "glsl-dither": ("npm", "glsl-dither", "1.0.1", {
        "LICENSE.md": "package/LICENSE.md", "8x8.glsl": "package/8x8.glsl",
        "example/index.frag": "package/example/index.frag", "example/index.vert": "package/example/index.vert"}),
    "glsl-luma": ("npm", "glsl-luma", "1.0.1", {"LICENSE.md": "package/LICENSE.md", "index.glsl": "package/index.glsl"}),
    "manimgl": ("pypi", "manimgl", "1.7.2", {
        "LICENSE.md": "manimgl-1.7.2/LICENSE.md",
        "mandelbrot_fractal/frag.glsl": "manimgl-1.7.2/manimlib/shaders/mandelbrot_fractal/frag.glsl",
        "mandelbrot_fractal/vert.glsl": "manimgl-1.7.2/manimlib/shaders/mandelbrot_fractal/vert.glsl",
        "inserts/finalize_color.glsl": "manimgl-1.7.2/manimlib/shaders/inserts/finalize_color.glsl",
        "inserts/complex_functions.glsl": "manimgl-1.7.2/manimlib/shaders/inserts/complex_functions.glsl"}),
    "kompute": ("pypi", "kp", "0.9.0", {
        "LICENSE": "kp-0.9.0/LICENSE",
        "ShaderOpMult.comp": "kp-0.9.0/src/shaders/glsl/ShaderOpMult.comp",
        "ShaderLogisticRegression.comp": "kp-0.9.0/src/shaders/glsl/ShaderLogisticRegression.comp"}),
}


def archive_url(registry: str, name: str, version: str) -> str:
    if registry == "npm":
        return NPM.format(name=name, base=name.split("/")[-1], version=version)
    request = urllib.request.Request(PYPI.format(name=name), headers={"Accept": "application/vnd.pypi.simple.v1+json"})
    with urllib.request.urlopen(request, timeout=60) as response:
        index = json.load(response)
    return next(f["url"] for f in index["files"] if f["filename"] == f"{name}-{version}.tar.gz")


def three_glsl(js: str) -> str:
    """The GLSL of a three.js module: its ``fragmentShader: /* glsl */`...``` string (a shader), or
    its ``export default /* glsl */`...``` (a chunk)."""
    found = re.search(r"(?:fragmentShader:|export default)\s*/\* glsl \*/`(.*?)`", js, re.S)
    if found is None or "${" in found.group(1):
        raise ValueError("no plain GLSL template string")
    return found.group(1)


def files(folder: str) -> dict[str, bytes]:
    registry, name, version, wanted = SOURCES[folder]
    with urllib.request.urlopen(archive_url(registry, name, version), timeout=120) as response:
        data = response.read()
    out = {}
    with tarfile.open(fileobj=io.BytesIO(data)) as tar:
        for here, inside in wanted.items():
            raw = tar.extractfile(inside).read()
            if inside.endswith(".js"):
                raw = three_glsl(raw.decode("utf-8")).encode("utf-8")
            out[here] = raw
    return out


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="compare instead of writing")
    a = p.parse_args()
    differ = 0
    for folder in SOURCES:
        for here, raw in files(folder).items():
            path = HERE / folder / here
            if a.check:
                if not path.is_file() or path.read_bytes() != raw:
                    print(f"differs: {path.relative_to(HERE)}")
                    differ += 1
            else:
                path.parent.mkdir(parents=True, exist_ok=True)
                path.write_bytes(raw)
    print("all files match the registries" if a.check and not differ else f"{differ} differ" if a.check else "written")
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
