"""Reading a skinned .glb back without Blender: where its skinned vertices are, as a glTF viewer puts them.

For tests of the posed exports: ``skinned_positions(doc, binary, node_name)`` applies the glTF skinning
formula (joint world matrix @ inverse bind matrix, weighted) to a node's mesh, so a test can compare
the file with what Blender shows. Only what ElliMann's exports use (float accessors, one primitive).
"""

import json
import struct

import numpy as np

COMPONENTS = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}
TYPES = {5126: "<f4", 5125: "<u4", 5123: "<u2", 5121: "<u1"}


def read_glb(path):
    """(the JSON document, the binary chunk) of a .glb file."""
    with open(path, "rb") as stream:
        data = stream.read()
    length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20 : 20 + length])
    rest = data[20 + length :]
    binary = rest[8 : 8 + struct.unpack_from("<I", rest, 0)[0]] if rest else b""
    return doc, binary


def accessor(doc, binary, index):
    """An accessor's values as a numpy array (count, components)."""
    info = doc["accessors"][index]
    view = doc["bufferViews"][info["bufferView"]]
    dtype = np.dtype(TYPES[info["componentType"]])
    width = COMPONENTS[info["type"]]
    start = view.get("byteOffset", 0) + info.get("byteOffset", 0)
    stride = view.get("byteStride", dtype.itemsize * width)
    raw = np.frombuffer(
        binary, dtype=np.uint8, count=stride * (info["count"] - 1) + dtype.itemsize * width, offset=start
    )
    rows = [
        np.frombuffer(raw[i * stride : i * stride + dtype.itemsize * width].tobytes(), dtype)
        for i in range(info["count"])
    ]
    values = np.array(rows, dtype=float)
    if info.get("normalized"):
        values /= np.iinfo(dtype).max
    return values


def node_matrix(node):
    if "matrix" in node:
        return np.array(node["matrix"], float).reshape(4, 4).T
    x, y, z, w = node.get("rotation", (0.0, 0.0, 0.0, 1.0))
    rotation = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    matrix = np.eye(4)
    matrix[:3, :3] = rotation * np.array(node.get("scale", (1.0, 1.0, 1.0)))
    matrix[:3, 3] = node.get("translation", (0.0, 0.0, 0.0))
    return matrix


def world_matrices(doc):
    """{node index: world matrix (4, 4)} from the scene's roots down."""
    parent = {child: i for i, node in enumerate(doc["nodes"]) for child in node.get("children", [])}
    out = {}

    def world(i):
        if i not in out:
            out[i] = (world(parent[i]) if i in parent else np.eye(4)) @ node_matrix(doc["nodes"][i])
        return out[i]

    for i in range(len(doc["nodes"])):
        world(i)
    return out


def skinned_positions(doc, binary, node_name):
    """(V, 3) positions of a skinned node's mesh as a viewer draws them (glTF's axes, Y up)."""
    index = next(i for i, n in enumerate(doc["nodes"]) if n.get("name") == node_name)
    node = doc["nodes"][index]
    primitive = doc["meshes"][node["mesh"]]["primitives"][0]
    positions = accessor(doc, binary, primitive["attributes"]["POSITION"])
    if "skin" not in node:
        return positions @ world_matrices(doc)[index][:3, :3].T + world_matrices(doc)[index][:3, 3]
    skin = doc["skins"][node["skin"]]
    inverse_bind = accessor(doc, binary, skin["inverseBindMatrices"]).reshape(-1, 4, 4).transpose(0, 2, 1)
    worlds = world_matrices(doc)
    joint_matrices = np.array([worlds[j] for j in skin["joints"]]) @ inverse_bind
    joints = accessor(doc, binary, primitive["attributes"]["JOINTS_0"]).astype(int)
    weights = accessor(doc, binary, primitive["attributes"]["WEIGHTS_0"])
    homogeneous = np.c_[positions, np.ones(len(positions))]
    out = np.zeros((len(positions), 4))
    for k in range(joints.shape[1]):
        out += weights[:, k : k + 1] * np.einsum("vij,vj->vi", joint_matrices[joints[:, k]], homogeneous)
    return out[:, :3]
