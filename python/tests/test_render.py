"""rtcl.render: the image of `rtcl render` as a numpy array. The renderer
itself is tested by the C++ suite; here, that the options reach it: the
array is the image the command writes for the same options (an 8-bit PNG,
read here with zlib), and bad options are refused."""
import os
import struct
import subprocess
import zlib
from pathlib import Path

import numpy as np
import pytest

import rtcl
from meshes import mesh_file, scenes_dir


def read_png(path):
    """An 8-bit RGB or RGBA PNG file as (height, width, 3) uint8 (zlib and
    the five row filters of the PNG specification)."""
    data = Path(path).read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos, idat = 8, b""
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert depth == 8 and colour in (2, 6) and interlace == 0
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    channels = 3 if colour == 2 else 4
    raw = zlib.decompress(idat)
    stride = width * channels
    out = np.zeros((height, stride), np.int32)
    for y in range(height):
        kind, row = raw[y * (stride + 1)], np.frombuffer(raw, np.uint8, stride, y * (stride + 1) + 1).astype(np.int32)
        up = out[y - 1] if y else np.zeros(stride, np.int32)
        if kind in (0, 2):
            out[y] = (row + (up if kind == 2 else 0)) & 255
            continue
        for x in range(stride):
            left = out[y, x - channels] if x >= channels else 0
            corner = up[x - channels] if x >= channels else 0
            if kind == 1:
                pred = left
            elif kind == 3:
                pred = (left + up[x]) // 2
            else:  # Paeth
                p = left + up[x] - corner
                pa, pb, pc = abs(p - left), abs(p - up[x]), abs(p - corner)
                pred = left if pa <= pb and pa <= pc else up[x] if pb <= pc else corner
            out[y, x] = (row[x] + pred) & 255
    return out.reshape(height, width, channels)[..., :3].astype(np.uint8)


def srgb_bytes(linear):
    """The 8-bit sRGB values the tool writes for a linear image."""
    c = np.clip(linear.astype(np.float64), 0.0, 1.0)
    encoded = np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1.0 / 2.4) - 0.055)
    return np.rint(encoded * 255.0).astype(np.int32)


def test_default_scene():
    image = rtcl.render(width=48, spp=1, depth=2)
    assert image.dtype == np.float32 and image.ndim == 3 and image.shape[1:] == (48, 3)
    assert np.all(np.isfinite(image)) and np.all(image >= 0)
    assert image.mean() > 0.01  # something is lit
    assert rtcl.render("default", 32, 24, depth=0).shape == (24, 32, 3)


@pytest.mark.skipif(not os.environ.get("RTCL_CLI"), reason="RTCL_CLI (the rtcl tool) not given")
@pytest.mark.parametrize("options", [
    dict(scene="showcase", width=40, height=30, spp=2, depth=3, sampler="sobol", seed=7, light_samples=2),
    dict(scene="default", width=40, height=32, spp=1, method="selective", selective_block=4),
    dict(scene="forest", width=40, height=24, spp=1, depth=1),
])
def test_same_image_as_the_command(tmp_path, monkeypatch, options):
    if options["scene"] == "forest":
        mesh_file("stanford_bunny/bunny.obj")  # the forest's bunny
        monkeypatch.setenv("RTCL_SCENES_DIR", str(scenes_dir()))
    out = tmp_path / "image.png"
    args = [os.environ["RTCL_CLI"], "render", "-q", "-o", str(out)]
    for key, value in options.items():
        args += ["--builtin", value] if key == "scene" else [f"--{key.replace('_', '-')}", str(value)]
    subprocess.run(args, check=True, capture_output=True)
    image = rtcl.render(**options)
    assert image.shape == (options["height"], options["width"], 3)
    # The same linear values, up to the rounding of the sRGB encoding.
    difference = np.abs(srgb_bytes(image) - read_png(out).astype(np.int32))
    assert difference.max() <= 1 and difference.mean() < 0.01
    # ... which tells these options apart.
    other = rtcl.render(**{**options, "seed": 99, "spp": 3})
    assert np.abs(srgb_bytes(other) - read_png(out).astype(np.int32)).max() > 8


def test_bad_options(monkeypatch):
    with pytest.raises(ValueError, match=r"render: width is 0; must be in \[1, 65536\]"):
        rtcl.render(width=0)
    with pytest.raises(ValueError, match="render: spp is 0"):
        rtcl.render(spp=0)
    with pytest.raises(ValueError, match="render: sampler is 'halton'; must be one of"):
        rtcl.render(sampler="halton")
    with pytest.raises(ValueError, match="render: method is 'cone'"):
        rtcl.render(method="cone")
    with pytest.raises(ValueError, match="render: min_weight"):
        rtcl.render(min_weight=float("nan"))
    with pytest.raises(ValueError, match='render: scene "no/such.json": no such file'):
        rtcl.render("no/such.json")
    with monkeypatch.context() as m:
        m.delenv("RTCL_SCENES_DIR", raising=False)
        with pytest.raises(ValueError, match="RTCL_SCENES_DIR|scenes directory"):
            rtcl.render("forest", width=8)
    with pytest.raises(TypeError, match="render: scene must be"):
        rtcl.render(3)
    with pytest.raises(ValueError, match='accel "nope"'):
        rtcl.render(width=8, accel="nope")
    with pytest.raises(ValueError, match='precision "nope"'):
        rtcl.render(width=8, precision="nope")


def test_scene_file(tmp_path):
    scene = tmp_path / "scene.json"
    scene.write_text('{"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0], "fov": 40},'
                     ' "lights": [{"position": [2, 2, 2]}], "materials": {"white": {}},'
                     ' "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "white"}]}')
    image = rtcl.render(scene, 16, 16)
    assert image.shape == (16, 16, 3)
    assert image[8, 8].sum() > image[0, 0].sum()  # the sphere in the middle, lit
    assert np.array_equal(rtcl.render(os.fspath(scene), 16, 16), rtcl.render(scene, 16, 16))


def test_emissive_triangles_light_a_scene_without_lights(tmp_path):
    """As `rtcl render`: with no light declared, the emissive triangles (the
    Cornell box's lamp, Ke = (17, 12, 4)) light the scene as the light
    {"type": "emissive"} whose intensity scales the brightest channel to 1
    would, with a note; without anything emitting, a warning."""
    obj = mesh_file("cornell_box/CornellBox-Original.obj")
    camera = '"camera": {"position": [0, 1, 3.9], "look_at": [0, 1, 0], "fov": 39.3}'
    objects = f'"objects": [{{"type": "mesh", "file": "{obj}"}}]'
    implicit, explicit = tmp_path / "implicit.json", tmp_path / "explicit.json"
    implicit.write_text("{" + camera + ", " + objects + "}")
    intensity = float(np.float32(1.0 / 17.0))
    explicit.write_text("{" + camera + f', "lights": [{{"type": "emissive", "intensity": {intensity!r}}}], '
                        + objects + "}")
    with pytest.warns(UserWarning, match=r'implicit.json: no light declared: its 2 emissive triangles light it as '
                                         r'area lights, as \{"type": "emissive", "intensity": 0.0588\}'):
        a = rtcl.render(implicit, 24, 24)
    b = rtcl.render(explicit, 24, 24)
    assert np.allclose(a, b, rtol=1e-5, atol=1e-5)
    lit = a.sum(axis=2) > 0.03
    assert lit.mean() > 0.5  # the walls and blocks are lit, not only the lamp
    dark = tmp_path / "dark.json"
    dark.write_text('{"camera": {"position": [0, 0, 3], "look_at": [0, 0, 0]}, "materials": {"m": {}},'
                    ' "objects": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}]}')
    with pytest.warns(UserWarning, match="dark.json: no light declared and no triangle emits light"):
        rtcl.render(dark, 8, 8)
    with pytest.warns(UserWarning, match='no light declared; method="beam" lights by point lights only'):
        rtcl.render(implicit, 8, 8, method="beam")
