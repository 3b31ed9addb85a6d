"""The files the add-on exchanges with the predictor, and the predictor's run; no bpy here, so
plain python3 can test it (tests/blender/exchange_test.py).

The mesh goes out as an OBJ and the skeleton as RigNet rig text, both written here in Blender's
own vertex and bone order; the predictor (`skinlab predict` or `skinlab-predict`) reads the OBJ
with its own reader, which keeps the file's vertex order, and writes the weights back as rig text,
`skin <vertex> <joint> <weight> ...`. So vertex k of the result is vertex k of the Blender mesh
by construction (integrations/blender/README.md says why not glTF).
"""

import os
import shutil
import subprocess

# rig_io's write_rig refuses these in a joint name; its reader splits on whitespace.
_UNSAFE = set(" \t\r\n\v\f#")


class PredictorError(Exception):
    """A failure to report in Blender: the predictor's own message, or a file that is wrong."""


def rig_names(names):
    """Names for the rig text, one per bone: the bone's own name when the rig text can carry it
    (no whitespace or '#', ASCII), else `skinlab_bone_<k>`; never two alike."""
    taken = set(names)
    out = []
    for k, name in enumerate(names):
        if name and name.isascii() and not (set(name) & _UNSAFE):
            out.append(name)
            continue
        alias = f"skinlab_bone_{k}"
        while alias in taken:
            alias += "_"
        taken.add(alias)
        out.append(alias)
    return out


def write_obj(path, positions, triangles):
    """`v` lines in vertex order (shortest round-trip decimals, so the predictor reads the very
    floats Blender holds) and `f` lines (1-based)."""
    with open(path, "w", encoding="ascii") as f:
        f.write("# written by the skinlab Blender add-on\n")
        f.writelines(f"v {x!r} {y!r} {z!r}\n" for x, y, z in positions)
        f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in triangles)


def write_rig(path, names, positions, parents):
    """RigNet rig text without `skin` lines: `joints`, one `root`, `hier parent child`. `parents`
    holds each joint's parent index, -1 for the root (exactly one)."""
    roots = [names[j] for j, p in enumerate(parents) if p < 0]
    if len(roots) != 1:
        raise PredictorError(f"the skeleton needs exactly one root bone, found {len(roots)}: "
                             + ", ".join(roots))
    with open(path, "w", encoding="ascii") as f:
        for name, (x, y, z) in zip(names, positions):
            f.write(f"joints {name} {x!r} {y!r} {z!r}\n")
        f.write(f"root {roots[0]}\n")
        f.writelines(f"hier {names[p]} {names[j]}\n" for j, p in enumerate(parents) if p >= 0)


def read_weights(path, num_vertices, names):
    """The `skin` lines of the predictor's rig text: one list of (joint index, weight) per
    vertex, joints indexed as in `names`. A line that does not fit (unknown joint, vertex out of
    range or twice, a vertex without a line, a bad number) is a PredictorError naming the file
    and line: nothing may be applied from an output that does not fit the mesh sent."""
    index = {name: j for j, name in enumerate(names)}
    weights = [None] * num_vertices
    with open(path, encoding="utf-8") as f:
        for number, line in enumerate(f, 1):
            words = line.split()
            if not words or words[0] != "skin":
                continue
            where = f"{path}:{number}"
            if len(words) < 2 or len(words) % 2 != 0:
                raise PredictorError(f"{where}: a skin line is 'skin VERTEX JOINT WEIGHT ...'")
            try:
                vertex = int(words[1])
                pairs = [(index[words[k]], float(words[k + 1])) for k in range(2, len(words), 2)]
            except KeyError as e:
                raise PredictorError(f"{where}: unknown joint {e}") from None
            except ValueError as e:
                raise PredictorError(f"{where}: {e}") from None
            if not 0 <= vertex < num_vertices:
                raise PredictorError(f"{where}: vertex {vertex} is out of range (the mesh has "
                                     f"{num_vertices} vertices)")
            if weights[vertex] is not None:
                raise PredictorError(f"{where}: vertex {vertex} has a second skin line")
            weights[vertex] = pairs
    missing = [v for v, w in enumerate(weights) if w is None]
    if missing:
        raise PredictorError(f"{path}: {len(missing)} of {num_vertices} vertices have no skin "
                             f"line (the first: {missing[0]})")
    return weights


def find_predictor(preference, model=""):
    """The predictor program: the preference (a path, or a name on PATH), else from PATH
    `skinlab-predict` (no libtorch: it starts in a tenth of the time) and then `skinlab`. A
    `model` directory without parameters.h5 (a training run, not a bundled model) can only be
    read by `skinlab`, so then `skinlab` comes first."""
    if preference:
        path = os.path.expanduser(preference)
        found = shutil.which(path)
        if found is None:
            raise PredictorError(f"the predictor '{preference}' (add-on preferences) is not an "
                                 "executable program")
        return found
    names = ["skinlab-predict", "skinlab"]
    if model and not os.path.isfile(os.path.join(os.path.expanduser(model), "parameters.h5")):
        names.reverse()
    for name in names:
        found = shutil.which(name)
        if found is not None:
            return found
    raise PredictorError("no predictor: neither 'skinlab' nor 'skinlab-predict' is on PATH; set "
                         "its path in the add-on's preferences")


def predictor_command(program, obj, rig, out, model="", extra=()):
    """`skinlab predict OBJ --rig RIG --out OUT [--model M]`; a program not named `skinlab`
    (`skinlab-predict`) takes the same arguments without the `predict` sub-command."""
    command = [program]
    if os.path.basename(program) == "skinlab":
        command.append("predict")
    command += [obj, "--rig", rig, "--out", out]
    if model:
        command += ["--model", os.path.expanduser(model)]
    command += list(extra)
    return command


def error_lines(stderr):
    """What the predictor said went wrong: its `error` lines (`skinlab: error: ...`,
    `[error] ...`), else the last non-empty lines of stderr."""
    lines = [line.strip() for line in stderr.replace("\r", "\n").splitlines() if line.strip()]
    errors = [line for line in lines if "error" in line.lower()]
    return "; ".join(errors or lines[-3:]) or "(no message on stderr)"


def run_predictor(command):
    """Runs the predictor; a PredictorError with its message when it cannot start or fails."""
    try:
        done = subprocess.run(command, stdin=subprocess.DEVNULL, capture_output=True, text=True,
                              errors="replace")
    except OSError as e:
        raise PredictorError(f"cannot run {command[0]}: {e.strerror}") from None
    if done.returncode != 0:
        raise PredictorError(f"{os.path.basename(command[0])} failed (exit status "
                             f"{done.returncode}): {error_lines(done.stderr)}")
    return done.stdout
