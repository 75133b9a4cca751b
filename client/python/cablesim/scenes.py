"""Scenes from a dict, a JSON file or text, or a text-format file.

A scene is a cablesim.v1.Scene (proto/cablesim/v1/scene.proto). Enum fields
are given by name (`"integrator": "IMPLICIT_EULER"`), as in the scene files
that `cablesim run` reads.
"""

import os
from typing import Any, Mapping, Union

from google.protobuf import json_format, text_format

from cablesim.errors import scene_error_from_json_parse, scene_error_from_text_parse
from cablesim.v1 import scene_pb2

# A file name (JSON, or text format by extension), JSON text, a dict in the
# protobuf JSON mapping, or a Scene message.
SceneLike = Union[str, "os.PathLike[str]", Mapping[str, Any], scene_pb2.Scene]

# The extensions `cablesim` reads as protobuf text format (README).
TEXT_FORMAT_EXTENSIONS = (".txtpb", ".textproto", ".pbtxt")


def load_scene(source: SceneLike) -> scene_pb2.Scene:
    """The Scene that `source` describes.

    `source` is a Scene (copied), a dict in the protobuf JSON mapping (field
    names as in scene files, enums by name), JSON text (starting with `{`),
    or the name of a scene file: protobuf text format when it ends in .txtpb,
    .textproto or .pbtxt, else protobuf JSON. Raises cablesim.Error
    (code INVALID_ARGUMENT; a ValueError too) for a malformed scene, its
    `field` the path as written in scene files ("cables[0].youngs_modulus";
    unknown fields are errors, as in `cablesim`), FileNotFoundError for a
    missing file.
    """
    if isinstance(source, scene_pb2.Scene):
        scene = scene_pb2.Scene()
        scene.CopyFrom(source)
        return scene
    if isinstance(source, Mapping):
        try:
            return json_format.ParseDict(source, scene_pb2.Scene())
        except json_format.ParseError as e:
            raise scene_error_from_json_parse(str(e), "scene") from None
    if isinstance(source, str) and source.lstrip().startswith("{"):
        try:
            return json_format.Parse(source, scene_pb2.Scene())
        except json_format.ParseError as e:
            raise scene_error_from_json_parse(str(e), "scene") from None
    path = os.fspath(source)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    if path.endswith(TEXT_FORMAT_EXTENSIONS):
        try:
            return text_format.Parse(text, scene_pb2.Scene())
        except text_format.ParseError as e:
            raise scene_error_from_text_parse(str(e), path) from None
    try:
        return json_format.Parse(text, scene_pb2.Scene())
    except json_format.ParseError as e:
        raise scene_error_from_json_parse(str(e), path) from None


def scene_to_dict(scene: scene_pb2.Scene) -> dict:
    """The scene as a dict in the protobuf JSON mapping (enums by name), the
    form load_scene() reads back."""
    return json_format.MessageToDict(scene, preserving_proto_field_name=True)
