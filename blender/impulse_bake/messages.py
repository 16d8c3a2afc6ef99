"""impulse's scene errors in the animator's terms: "Plane: shape Convex Hull: …" rather than
the scene format's file position and field path, and every body's problem at once (the engine
stops at the first)."""

import re

#: A scene error's source position (``<dict>:85:19: ``, ``scene.json:4:56: ``).
_POSITION = re.compile(r"^[^\s:]*:\d+:\d+: ")

#: The scene format's path of a body's or joint's field: ``bodies[1] ("Plane").shape.points: ``.
_PATH = re.compile(r'^(bodies|joints)\[(\d+)\](?: \("(?:[^"\\]|\\.)*"\))?((?:\.\w+|\[\d+\]|\["[^"]*"\])*): ')

#: The world builder's form of a body's field: ``cannot build the world: body 1 ("Plane"): shape.points: ``.
_BODY = re.compile(r'^(?:[^:]*: )?body (\d+)(?: \("(?:[^"\\]|\\.)*"\))?: ((?:\w+)(?:\.\w+|\[\d+\])*): ')

#: Scene-format fields of a body as the Physics panel names them.
_FIELDS = {
    "material.friction": "Friction",
    "material.restitution": "Bounciness",
    "mass": "Mass",
    "linear_damping": "Damping Translation",
    "angular_damping": "Damping Rotation",
    "position": "its location",
    "orientation": "its rotation",
    "keyframes": "its animation",
}


def translate(message, info):
    """The engine's scene error ``message`` about the read scene ``info``
    (:class:`scene_reader.SceneInfo`) led by the object's (or the constraint's) name and the
    setting's name as the panel shows it, without the file position or the field path."""
    message = _POSITION.sub("", message.strip())
    body_form = _BODY.match(message)
    if body_form is not None:
        message = f"bodies[{body_form.group(1)}].{body_form.group(2)}: " + message[body_form.end():]
    found = _PATH.match(message)
    if found is None:
        return f"{info.scene.get('name', 'scene')}: {message}"
    rest = message[found.end():]
    which, index, path = found.group(1), int(found.group(2)), found.group(3).lstrip(".")
    if which == "joints":
        joints = info.scene.get("joints", [])
        name = joints[index]["name"] if index < len(joints) else f"constraint {index + 1}"
        return f"{name}: {rest}"
    if index >= len(info.bodies):
        return f"{info.scene.get('name', 'scene')}: {rest}"
    body = info.bodies[index]
    if path.startswith("shape"):
        term = f"shape {body.shape_label}"
    else:
        term = next((label for key, label in _FIELDS.items() if path.startswith(key)), None)
    return f"{body.object_name}: {term}: {rest}" if term else f"{body.object_name}: {rest}"


def every_problem(info, error, build):
    """Every body's and joint's problem of the read scene ``info``, in the animator's terms:
    each body is built alone, then each joint with all the bodies, by ``build`` (a function of
    a scene dict that raises the engine's scene error); the original ``error`` when none fails
    alone."""
    scene = info.scene
    problems = []
    for body in scene["bodies"]:
        alone = {key: value for key, value in scene.items() if key not in ("bodies", "joints")}
        alone["bodies"] = [body]
        try:
            build(alone)
        except Exception as failure:  # the engine's SceneError, whatever its class
            index = scene["bodies"].index(body)
            problems.append(translate(_renumber(str(failure), index), info))
    if not problems:
        for joint in scene.get("joints", []):
            try:
                build(dict(scene, joints=[joint]))
            except Exception as failure:
                index = scene["joints"].index(joint)
                problems.append(translate(_renumber(str(failure), index, "joints"), info))
    return problems or [translate(str(error), info)]


def _renumber(message, index, which="bodies"):
    """A message about ``which[0]`` (or ``body 0``) of a one-item scene as one about
    ``which[index]``."""
    message = re.sub(rf"{which}\[0\]", f"{which}[{index}]", message, count=1)
    return re.sub(r"\bbody 0\b", f"body {index}", message, count=1) if which == "bodies" else message
