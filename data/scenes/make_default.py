#!/usr/bin/env python3
"""Writes default.gltf: the small self-contained demo scene (a furnished room lit by a
ceiling panel). Standard library only; run from this directory to regenerate."""
import base64, json, math, struct, zlib

buf = bytearray()
views, accessors, meshes = [], [], []


def add_view(data, target):
    while len(buf) % 4:
        buf.append(0)
    views.append({"buffer": 0, "byteOffset": len(buf), "byteLength": len(data), "target": target})
    buf.extend(data)
    return len(views) - 1


def add_accessor(values, comps, ctype, target, minmax=False):
    fmt = {5126: "f", 5125: "I"}[ctype]
    flat = [c for v in values for c in (v if comps > 1 else (v,))]
    view = add_view(struct.pack("<%d%s" % (len(flat), fmt), *flat), target)
    acc = {"bufferView": view, "componentType": ctype, "count": len(values),
           "type": {1: "SCALAR", 2: "VEC2", 3: "VEC3"}[comps]}
    if minmax:
        acc["min"] = [min(v[i] for v in values) for i in range(comps)]
        acc["max"] = [max(v[i] for v in values) for i in range(comps)]
    accessors.append(acc)
    return len(accessors) - 1


def add_mesh(name, pos, nrm, uv, idx, material):
    meshes.append({"name": name, "primitives": [{
        "attributes": {"POSITION": add_accessor(pos, 3, 5126, 34962, True),
                       "NORMAL": add_accessor(nrm, 3, 5126, 34962),
                       "TEXCOORD_0": add_accessor(uv, 2, 5126, 34962)},
        "indices": add_accessor(idx, 1, 5125, 34963), "material": material}]})
    return len(meshes) - 1


def quad_mesh(name, w, h, material, tiles=1.0):
    # Unit quad in the XZ plane facing +Y, centred at the origin.
    pos = [(-w / 2, 0, -h / 2), (w / 2, 0, -h / 2), (w / 2, 0, h / 2), (-w / 2, 0, h / 2)]
    nrm = [(0, 1, 0)] * 4
    uv = [(0, 0), (tiles, 0), (tiles, tiles), (0, tiles)]
    return add_mesh(name, pos, nrm, uv, [0, 2, 1, 0, 3, 2], material)


def box_mesh(name, material):
    pos, nrm, uv, idx = [], [], [], []
    for axis in range(3):
        for sign in (-1, 1):
            n = [0, 0, 0]; n[axis] = sign
            u = [0, 0, 0]; u[(axis + 1) % 3] = 1
            v = [0, 0, 0]; v[(axis + 2) % 3] = 1
            base = len(pos)
            for (a, b) in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                pos.append(tuple(0.5 * (n[i] + a * u[i] + b * v[i]) for i in range(3)))
                nrm.append(tuple(n)); uv.append(((a + 1) / 2, (b + 1) / 2))
            tri = [0, 1, 2, 0, 2, 3] if sign > 0 else [0, 2, 1, 0, 3, 2]
            idx += [base + t for t in tri]
    return add_mesh(name, pos, nrm, uv, idx, material)


def sphere_mesh(name, rings, segs, material):
    pos, nrm, uv, idx = [], [], [], []
    for i in range(rings + 1):
        th = math.pi * i / rings
        for j in range(segs + 1):
            ph = 2 * math.pi * j / segs
            p = (math.sin(th) * math.cos(ph), math.cos(th), -math.sin(th) * math.sin(ph))
            pos.append(p); nrm.append(p); uv.append((j / segs, i / rings))
    for i in range(rings):
        for j in range(segs):
            a, b = i * (segs + 1) + j, (i + 1) * (segs + 1) + j
            if i: idx += [a, b, a + 1]
            if i != rings - 1: idx += [a + 1, b, b + 1]
    return add_mesh(name, pos, nrm, uv, idx, material)


def torus_mesh(name, R, r, n1, n2, material):
    pos, nrm, uv, idx = [], [], [], []
    for i in range(n1 + 1):
        a = 2 * math.pi * i / n1
        for j in range(n2 + 1):
            b = 2 * math.pi * j / n2
            n = (math.cos(a) * math.cos(b), math.sin(b), -math.sin(a) * math.cos(b))
            c = (R * math.cos(a), 0, -R * math.sin(a))
            pos.append(tuple(c[k] + r * n[k] for k in range(3))); nrm.append(n); uv.append((i / n1, j / n2))
    for i in range(n1):
        for j in range(n2):
            p, q = i * (n2 + 1) + j, (i + 1) * (n2 + 1) + j
            idx += [p, q, p + 1, p + 1, q, q + 1]
    return add_mesh(name, pos, nrm, uv, idx, material)


def png(w, h, pixel):
    raw = b"".join(b"\0" + bytes(c for x in range(w) for c in pixel(x, y)) for y in range(h))
    chunk = lambda t, d: struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


# Brick-like tiles for the floor texture.
def tile(x, y):
    row = y // 8
    edge = y % 8 == 0 or (x + (4 if row % 2 else 0)) % 16 == 0
    return (90, 80, 70) if edge else ((180, 120, 80) if (row + x // 16) % 3 else (160, 100, 70))


materials = [
    {"name": "floor", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0, "roughnessFactor": 0.7}},
    {"name": "wall", "pbrMetallicRoughness": {"baseColorFactor": [0.75, 0.73, 0.7, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0}},
    {"name": "wall-red", "pbrMetallicRoughness": {"baseColorFactor": [0.7, 0.15, 0.12, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0}},
    {"name": "wall-blue", "pbrMetallicRoughness": {"baseColorFactor": [0.15, 0.25, 0.6, 1], "metallicFactor": 0.0, "roughnessFactor": 1.0}},
    {"name": "panel", "emissiveFactor": [1.0, 0.95, 0.85], "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 12.0}},
     "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.8, 0.8, 1], "metallicFactor": 0.0}},
    {"name": "gold", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 0.78, 0.34, 1], "metallicFactor": 1.0, "roughnessFactor": 0.25}},
    {"name": "plastic", "pbrMetallicRoughness": {"baseColorFactor": [0.1, 0.5, 0.2, 1], "metallicFactor": 0.0, "roughnessFactor": 0.4}},
    {"name": "crate", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "baseColorFactor": [0.9, 0.9, 1.0, 1], "metallicFactor": 0.0, "roughnessFactor": 0.9}},
]

m_floor = quad_mesh("floor", 6, 6, 0, 4.0)
m_wall = quad_mesh("wall", 6, 3, 1)
m_red = quad_mesh("wall-red", 3, 6, 2)
m_blue = quad_mesh("wall-blue", 3, 6, 3)
m_panel = quad_mesh("panel", 1.6, 1.0, 4)
m_sphere = sphere_mesh("sphere", 24, 48, 5)
m_torus = torus_mesh("torus", 0.35, 0.12, 40, 16, 6)
m_box = box_mesh("box", 7)

s = math.sqrt(0.5)
nodes = [
    {"name": "floor", "mesh": m_floor},
    {"name": "ceiling", "mesh": m_wall, "translation": [0, 3, 0], "rotation": [1, 0, 0, 0], "scale": [1, 1, 2]},
    {"name": "back", "mesh": m_wall, "translation": [0, 1.5, -3], "rotation": [s, 0, 0, s]},
    {"name": "left", "mesh": m_red, "translation": [-3, 1.5, 0], "rotation": [0, 0, -s, s]},
    {"name": "right", "mesh": m_blue, "translation": [3, 1.5, 0], "rotation": [0, 0, s, s]},
    {"name": "panel", "mesh": m_panel, "translation": [0, 2.99, -1.0], "rotation": [1, 0, 0, 0]},
    {"name": "props", "translation": [0, 0, -1.2], "children": [7, 8, 9]},
    {"name": "sphere", "mesh": m_sphere, "translation": [-0.9, 0.5, 0], "scale": [0.5, 0.5, 0.5]},
    {"name": "torus", "mesh": m_torus, "translation": [0.9, 0.12, 0.3]},
    {"name": "crate", "mesh": m_box, "translation": [0.2, 0.35, -0.8], "rotation": [0, 0.2588, 0, 0.9659], "scale": [0.7, 0.7, 0.7]},
    {"name": "camera", "camera": 0, "translation": [0, 1.5, 2.2], "rotation": [-0.0998, 0, 0, 0.995]},
]

gltf = {
    "asset": {"version": "2.0", "generator": "fovea data/scenes/make_default.py"},
    "extensionsUsed": ["KHR_materials_emissive_strength"],
    "scene": 0,
    "scenes": [{"name": "room", "nodes": [0, 1, 2, 3, 4, 5, 6, 10]}],
    "nodes": nodes,
    "meshes": meshes,
    "materials": materials,
    "cameras": [{"type": "perspective", "perspective": {"yfov": 1.5, "znear": 0.05, "aspectRatio": 0.9}}],
    "textures": [{"source": 0, "sampler": 0}],
    "samplers": [{"magFilter": 9729, "minFilter": 9987, "wrapS": 10497, "wrapT": 10497}],
    "images": [{"name": "tiles", "uri": "data:image/png;base64," + base64.b64encode(png(64, 64, tile)).decode()}],
    "accessors": accessors,
    "bufferViews": views,
    "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64," + base64.b64encode(bytes(buf)).decode()}],
}
with open("default.gltf", "w") as f:
    json.dump(gltf, f, separators=(",", ":"))
