"""cablesim.Error and the field paths of scene errors. Standard library only,
so that it imports where grpc and protobuf are not installed."""

import re
from typing import Optional


class Error(Exception):
    """A call the service refused or could not complete, or a scene the
    package could not read. `code` is the gRPC status name
    ("INVALID_ARGUMENT", "NOT_FOUND", "UNAVAILABLE", ...), `details` the
    message; for a bad scene `field` is the field's path as written in scene
    files, snake_case with indices (e.g. "cables[0].youngs_modulus"), and
    `details` starts with it."""

    def __init__(self, code: str, details: str, field: Optional[str] = None):
        super().__init__("%s: %s" % (code, details))
        self.code = code
        self.details = details
        self._field = field

    @property
    def field(self) -> Optional[str]:
        if self._field is not None:
            return self._field
        head, sep, _ = self.details.partition(": ")
        if head in ("scene_json", "base_json"):  # the server's prefix for JSON text
            head, sep, _ = self.details[len(head) + 2:].partition(": ")
        return head if sep and self.code == "INVALID_ARGUMENT" and " " not in head else None


class SceneError(Error, ValueError):
    """A scene the package could not read (a ValueError too, as before):
    code INVALID_ARGUMENT, `field` the path of the field at fault."""

    def __init__(self, field: str, reason: str, where: str = ""):
        details = "%s: %s" % (field, reason) if field else reason
        if where:
            details = "%s: %s" % (where, details)
        super().__init__("INVALID_ARGUMENT", details, field or None)


def snake_case(name: str) -> str:
    """youngsModulus -> youngs_modulus (names already snake_case unchanged)."""
    return re.sub(r"(?<=[a-z0-9])([A-Z])", lambda m: "_" + m.group(1).lower(), name)


def snake_case_path(path: str) -> str:
    """A protobuf JSON parser's path ("Scene.cables[0].youngsModulus") as
    written in scene files ("cables[0].youngs_modulus")."""
    parts = path.split(".")
    if parts and parts[0] == "Scene":
        parts = parts[1:]
    return ".".join(snake_case(p) for p in parts if p)


def scene_error_from_json_parse(message: str, where: str = "") -> SceneError:
    """The SceneError for protobuf's json_format.ParseError text, e.g.
    'Failed to parse cables field: Message type "cablesim.v1.Cable" has no
    field named "youngs_modulos" at "Scene.cables[0]".' ->
    field cables[0].youngs_modulos, reason 'unknown field'."""
    m = re.search(r'has no field named "([^"]+)" at "([^"]+)"', message)
    if m:
        parent = snake_case_path(m.group(2))
        field = (parent + "." if parent else "") + m.group(1)
        return SceneError(field, "unknown field", where)
    m = re.search(r"^(?:Failed to parse \w+ field: )*(.*?) at (Scene[\w.\[\]]*?)\.*$",
                  message.split("\n")[0])
    if m:
        return SceneError(snake_case_path(m.group(2)), m.group(1), where)
    return SceneError("", message.split("\n")[0], where)


def scene_error_from_text_parse(message: str, where: str = "") -> SceneError:
    """The SceneError for protobuf's text_format.ParseError text
    ('4:2 : Message type "cablesim.v1.Cable" has no field named "lenght".'):
    text format reports a line and column, not a path, so `field` is the
    field's own name and the details name the line."""
    position, _, rest = message.partition(" : ")
    m = re.search(r'has no field named "([^"]+)"', rest)
    where = "%s:%s" % (where, position) if where else "line:column " + position
    if m:
        return SceneError(m.group(1), "unknown field", where)
    return SceneError("", rest or message, where)
