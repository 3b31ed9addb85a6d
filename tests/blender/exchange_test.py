"""The Blender add-on's exchange with the predictor (integrations/blender/skinlab_skin/exchange.py)
without Blender: the files it writes, the weights it reads back and the messages it reports.

    python3 tests/blender/exchange_test.py    (ctest: blender_addon_exchange, fast)
"""

import os
import stat
import sys
import tempfile
import unittest
from pathlib import Path

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "integrations" / "blender" / "skinlab_skin"))
import exchange  # noqa: E402
from exchange import PredictorError  # noqa: E402


class Exchange(unittest.TestCase):
    def setUp(self):
        self.dir = tempfile.TemporaryDirectory()
        self.path = Path(self.dir.name)

    def tearDown(self):
        self.dir.cleanup()

    def write(self, name, text):
        (self.path / name).write_text(text)
        return str(self.path / name)

    def test_rig_names_keep_safe_names_and_alias_the_rest(self):
        self.assertEqual(exchange.rig_names(["hips", "upper arm.L", "Kopf#1", "épaule", ""]),
                         ["hips", "skinlab_bone_1", "skinlab_bone_2", "skinlab_bone_3",
                          "skinlab_bone_4"])
        # an alias never takes a name the armature has
        self.assertEqual(exchange.rig_names(["a b", "skinlab_bone_0"]),
                         ["skinlab_bone_0_", "skinlab_bone_0"])

    def test_obj_and_rig_round_trip_floats_exactly(self):
        x = 0.1 + 0.2  # a double with no short decimal
        obj, rig = str(self.path / "m.obj"), str(self.path / "m_rig.txt")
        exchange.write_obj(obj, [(x, -x, 1e-20), (1.0, 2.0, 3.0), (0.0, 1.0, 0.0)], [(0, 1, 2)])
        lines = Path(obj).read_text().splitlines()
        self.assertEqual([float(v) for v in lines[1].split()[1:]], [x, -x, 1e-20])
        self.assertEqual(lines[-1], "f 1 2 3")
        exchange.write_rig(rig, ["root", "child"], [(0.0, x, 0.0), (1.0, 1.0, 1.0)], [-1, 0])
        self.assertEqual(Path(rig).read_text(),
                         f"joints root 0.0 {x!r} 0.0\njoints child 1.0 1.0 1.0\nroot root\n"
                         "hier root child\n")

    def test_rig_needs_one_root(self):
        with self.assertRaisesRegex(PredictorError, "exactly one root bone, found 2: a, b"):
            exchange.write_rig(str(self.path / "r.txt"), ["a", "b"], [(0, 0, 0)] * 2, [-1, -1])

    def test_read_weights(self):
        out = self.write("w_rig.txt", "joints a 0 0 0\njoints b 1 0 0\nroot a\nhier a b\n"
                                      "skin 1 b 1\nskin 0 a 0.25 b 0.75\n")
        self.assertEqual(exchange.read_weights(out, 2, ["a", "b"]), [[(0, 0.25), (1, 0.75)], [(1, 1.0)]])

    def test_read_weights_refuses_what_does_not_fit(self):
        cases = {
            "skin 0 a 1\nskin 1 c 1\n": ":2: unknown joint 'c'",
            "skin 0 a 1\nskin 2 a 1\n": ":2: vertex 2 is out of range \\(the mesh has 2 vertices\\)",
            "skin 0 a 1\nskin 0 a 1\n": ":2: vertex 0 has a second skin line",
            "skin 0 a 1\n": ": 1 of 2 vertices have no skin line \\(the first: 1\\)",
            "skin 0 a one\nskin 1 a 1\n": ":1: could not convert",
            "skin 0 a\nskin 1 a 1\n": ":1: a skin line is 'skin VERTEX JOINT WEIGHT ...'",
        }
        for text, message in cases.items():
            with self.subTest(text=text):
                with self.assertRaisesRegex(PredictorError, "w_rig.txt" + message):
                    exchange.read_weights(self.write("w_rig.txt", text), 2, ["a", "b"])

    def test_command_per_program(self):
        self.assertEqual(exchange.predictor_command("/opt/bin/skinlab", "m.obj", "r.txt", "o.txt"),
                         ["/opt/bin/skinlab", "predict", "m.obj", "--rig", "r.txt", "--out", "o.txt"])
        self.assertEqual(
            exchange.predictor_command("/x/skinlab-predict", "m.obj", "r.txt", "o.txt", "/m"),
            ["/x/skinlab-predict", "m.obj", "--rig", "r.txt", "--out", "o.txt", "--model", "/m"])

    def fake_predictor(self, body):
        program = self.path / "skinlab-predict"
        program.write_text("#!/bin/sh\n" + body + "\n")
        program.chmod(program.stat().st_mode | stat.S_IXUSR)
        return str(program)

    def test_a_failing_predictor_is_reported_with_its_message(self):
        program = self.fake_predictor(
            "echo 'loading' >&2; echo 'skinlab: error: m.obj:3: vertex 2 is NaN' >&2; exit 1")
        with self.assertRaisesRegex(PredictorError, r"^skinlab-predict failed \(exit status 1\): "
                                                    r"skinlab: error: m.obj:3: vertex 2 is NaN$"):
            exchange.run_predictor([program])
        silent = self.fake_predictor("echo 'last words' >&2; exit 3")
        with self.assertRaisesRegex(PredictorError, r"\(exit status 3\): last words$"):
            exchange.run_predictor([silent])
        self.assertEqual(exchange.run_predictor([self.fake_predictor("echo ok")]), "ok\n")

    def test_find_predictor(self):
        program = self.fake_predictor("exit 0")
        self.assertEqual(exchange.find_predictor(program), program)
        with self.assertRaisesRegex(PredictorError, "'/no/such/skinlab' .* is not an executable"):
            exchange.find_predictor("/no/such/skinlab")
        path = os.environ["PATH"]
        try:
            os.environ["PATH"] = str(self.path)
            self.assertEqual(exchange.find_predictor(""), program)  # skinlab-predict on PATH
            # With both on PATH: skinlab-predict, unless the model is a run it cannot read.
            both = self.path / "both"
            both.mkdir()
            for name in ("skinlab", "skinlab-predict"):
                (both / name).symlink_to(program)
            os.environ["PATH"] = str(both)
            self.assertEqual(exchange.find_predictor(""), str(both / "skinlab-predict"))
            bundled = self.path / "bundled"
            bundled.mkdir()
            (bundled / "parameters.h5").write_bytes(b"")
            self.assertEqual(exchange.find_predictor("", str(bundled)),
                             str(both / "skinlab-predict"))
            run = self.path / "run"
            run.mkdir()
            self.assertEqual(exchange.find_predictor("", str(run)), str(both / "skinlab"))
            os.environ["PATH"] = str(self.path / "empty")
            with self.assertRaisesRegex(PredictorError, "neither 'skinlab' nor 'skinlab-predict'"):
                exchange.find_predictor("")
        finally:
            os.environ["PATH"] = path


if __name__ == "__main__":
    unittest.main()
