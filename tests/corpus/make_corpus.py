#!/usr/bin/env python3
"""Writes the hostile-input corpus: one input per case and, beside it, CASE.expect with the
pieces its refusal message must contain ({path} stands for the input's path). Every case here
was once crashed on or wrongly accepted; tests/saltus/corpus_test.cpp runs them all through the
readers (under ASan in the test command). Run from anywhere; it rewrites the folders it owns."""
import os
import shutil

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))

INERTIA = '<inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/>'


def urdf(body, joint=""):
    return ('<?xml version="1.0"?>\n<robot name="r">\n  <link name="base"/>\n'
            '  <link name="arm">\n' + body + '\n  </link>\n' + (joint or
            '  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 1 0"/>\n'
            '    <limit lower="-1" upper="1" effort="10" velocity="3"/></joint>\n') + '</robot>\n')


def inertial(mass="1", inertia=INERTIA, origin=""):
    return '    <inertial>' + origin + '<mass value="' + mass + '"/>' + inertia + '</inertial>'


URDF = {
    "mass_nan": (urdf(inertial("nan")), ["{path}:5:", "mass [nan]"]),
    "mass_text": (urdf(inertial("abc")), ["{path}:5:", "mass [abc]"]),
    "inertia_nan": (urdf(inertial(inertia=INERTIA.replace('ixx="0.1"', 'ixx="nan"'))), ["{path}:5:", "ixx is 'nan'"]),
    "negative_effort": (urdf(inertial(), '  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>'
                        '<axis xyz="0 1 0"/>\n    <limit lower="-1" upper="1" effort="-10" velocity="3"/></joint>\n'),
                        ["{path}", "'j'", "effort"]),
    "box_size_nan": (urdf(inertial() + '\n    <visual><geometry><box size="1 nan 1"/></geometry></visual>'),
                     ["{path}", "box"]),
    "binary": (b"\x7fELF\x02\x01\x01\x00" + bytes(range(256)), ["{path}:1:", "NUL byte", "binary content"]),
    "empty": ("", ["{path}", "empty"]),
    "not_xml": ("name: robot\nlinks: []\n", ["{path}:1:", "expected a URDF", "'name: robot"]),
    "cut_utf8": (b'<?xml version="1.0"?>\n<robot name="\xd7', ["{path}:2:", "not UTF-8"]),  # TinyXML over-read
    "bom_only": (b" \xef\xbb\xbf\xbf", ["{path}:1:", "not UTF-8"]),
    "truncated": (urdf(inertial())[:150], ["{path}:", "not well-formed XML"]),
    "box_huge": (urdf(inertial() + '\n    <visual><geometry><box size="1e300 1 1"/></geometry></visual>'),
                 ["{path}", "at most 1e6 m", "1e+300"]),
    "deep_nesting": ('<?xml version="1.0"?>\n<robot name="r">\n' + "<a>" * 120 + "</a>" * 120 + "\n</robot>\n",
                     ["{path}:3:", "nested deeper than 100 levels"]),
    # converted before checked: "mass must be positive, got 0" quoted a value never written
    "mass_underflow": (urdf(inertial("1e-400")), ["{path}:5:", "'1e-400' is out of the range of a double"]),
    "axis_underflow": (urdf(inertial(), '  <joint name="j" type="revolute"><parent link="base"/><child link="arm"/>\n'
                       '    <axis xyz="1e-320 0 0"/><limit lower="-1" upper="1" effort="10" velocity="3"/></joint>\n'),
                       ["{path}:8:", "joint 'j': axis must be a non-zero vector", '<axis xyz="1e-320 0 0"/>']),
    "entity_bomb": ('<?xml version="1.0"?>\n<!DOCTYPE robot [\n<!ENTITY a "aaaaaaaaaa">\n'
                    + "".join('<!ENTITY ' + chr(98 + i) + ' "' + ("&" + chr(97 + i) + ";") * 10 + '">\n' for i in range(9))
                    + ']>\n<robot name="&j;"><link name="l"/></robot>\n', ["{path}:2:", "a DTD with declarations"]),
}

SCENE_HEAD = open(os.path.join(ROOT, "models", "scenes", "ball_drop.yaml")).read()

SCENARIO = {
    "comma_line": (",\n", ["{path}:"]),  # yaml-cpp's LoadAll never ended on it (issue #1040)
    "second_document": (SCENE_HEAD + "---\nmodel: {point_mass: {mass: -5}}\n", ["{path}:", "a second YAML document"]),
    "gravity_huge": (SCENE_HEAD.replace("model:\n", "gravity: [0, 0, -1e300]\nmodel:\n", 1),
                     ["{path}:", "gravity:", "at most 1000 m/s^2", "-1e+300"]),
    "velocity_huge": (SCENE_HEAD.replace("  q: {z: height}\n", "  q: {z: height}\n  v: {z: -1e308}\n"),
                      ["{path}:", "initial.v.z:", "at most 100000", "m/s", "-1e+308"]),
    "starts_inside_ground": (SCENE_HEAD.replace("height: 1.0 ", "height: -1.0"),
                             ["{path}:", ": initial: contact 'ball' starts 1 m inside surface 'ground'"]),
    "mass_underflow": (SCENE_HEAD.replace("mass: ", "mass: 1e-400 #", 1),
                       ["{path}:", "'1e-400' is out of the range of a double"]),
    "directions_huge": (SCENE_HEAD.replace("    friction: 0\n", "    friction: 0.5\n    directions: 100000000\n"),
                        ["{path}:", "directions:", "at most 64", "100000000"]),
    "duration_huge": (SCENE_HEAD + "duration: 1e20\n", None),  # read fine; the step count is the simulate's check
    "joint_beyond_stop": (
        "name: beyond_stop\nmodel: {urdf: ../../data/urdf/limits.urdf}\njoint_limits: true\n"
        "initial: {q: {rev: 3, pris: -0.5}}\n",
        ["{path}:4:", "stop 'rev_upper' starts 1 rad beyond its upper limit 2 rad",
         "stop 'pris_lower' starts 0.4 m beyond its lower limit -0.1 m"]),
}
SCENARIO = {k: v for k, v in SCENARIO.items() if v[1] is not None}

PROBLEM_HEAD = open(os.path.join(ROOT, "models", "problems", "point_mass_drop.yaml")).read()
PROBLEM = {
    "n_huge": (PROBLEM_HEAD.replace("  N: ", "  N: 1000000000 #", 1), ["{path}:", "mesh.N:", "1 to 10000", "1000000000"]),
    "ipopt_unknown": (PROBLEM_HEAD.replace("\nipopt:\n", "\nipopt:\n  no_such_option: 1\n"),
                      ["{path}:", "ipopt.no_such_option:", "unknown Ipopt option"]),
    "ipopt_bad_value": (PROBLEM_HEAD.replace("\nipopt:\n", "\nipopt:\n  max_iter: many\n"),
                        ["{path}:", "ipopt.max_iter:", "invalid value 'many'", "an integer"]),
    "task_ipopt_unknown": (PROBLEM_HEAD + "task_ipopt: {no_such_option: 1}\n",
                           ["{path}:", "task_ipopt.no_such_option:", "unknown Ipopt option"]),
}

HEADER = "t,q.z,v.z,contact.ball.gap,contact.ball.vn,contact.ball.vt,contact.ball.pn,contact.ball.pt\n"
ROW = "0,1,0,1,0,0,0,0\n"
TRAJECTORY = {
    "nan": (HEADER + ROW + "0.001,nan,0,1,0,0,0,0\n", ["{path}:3:", "q.z", "'nan'"]),
    "inf": (HEADER + ROW + "0.001,1,inf,1,0,0,0,0\n", ["{path}:3:", "v.z", "'inf'"]),
    "overflow": (HEADER + ROW + "0.001,1e400,0,1,0,0,0,0\n", ["{path}:3:", "q.z", "'1e400'"]),
    "duplicate_column": (HEADER.replace("v.z", "q.z") + ROW, ["{path}:1:", "q.z"]),
    "decreasing_time": (HEADER + ROW + "0.002,1,0,1,0,0,0,0\n0.001,1,0,1,0,0,0,0\n", ["{path}:4:", "t"]),
    "coordinate_huge": (HEADER + ROW + "0.001,1e308,0,1,0,0,0,0\n", ["{path}:3:", "q.z", "1e308 is beyond the bound"]),
    "time_huge": (HEADER + ROW + "1e308,1,0,1,0,0,0,0\n", ["{path}:3:", "column 't'", "beyond the bound of 1e9 s"]),
    "nul_in_number": (HEADER + ROW + "0.001,0.5\x005,0,1,0,0,0,0\n", ["{path}:3:", "NUL byte"]),
}


def write(folder, name, ext, content, expect):
    os.makedirs(folder, exist_ok=True)
    mode = "wb" if isinstance(content, bytes) else "w"
    with open(os.path.join(folder, name + ext), mode) as f:
        f.write(content)
    with open(os.path.join(folder, name + ".expect"), "w") as f:
        f.write("\n".join(expect) + "\n")


def main():
    for kind, cases, ext in (("urdf", URDF, ".urdf"), ("scenario", SCENARIO, ".yaml"), ("problem", PROBLEM, ".yaml"),
                             ("trajectory", TRAJECTORY, ".csv")):
        folder = os.path.join(HERE, kind)
        shutil.rmtree(folder, ignore_errors=True)
        for name, (content, expect) in sorted(cases.items()):
            write(folder, name, ext, content, expect)
    # Saved solutions: the test solution with one value changed.
    folder = os.path.join(HERE, "solution")
    shutil.rmtree(folder, ignore_errors=True)
    source = open(os.path.join(ROOT, "tests", "data", "solutions", "point_mass_drop_inelastic", "variables.csv")).read()
    lines = source.splitlines(keepends=True)
    h = next(i for i, l in enumerate(lines) if l.startswith("h[1,0]"))
    cases = {
        "negative_element": (lines[:h] + ["h[1,0],-0.01\n"] + lines[h + 1:], ["variables.csv: variable 'h[1,0]'", "positive element length", "-0.01"]),
        "element_huge": (lines[:h] + ["h[1,0],1e308\n"] + lines[h + 1:], ["variables.csv: variable 'h[1,0]'", "at most h_max", "1e+308"]),
        "truncated": (lines[:len(lines) // 2], ["variables.csv", "missing"]),
        "order_huge": ([l.replace("# P: 4", "# P: 100000") for l in lines], ["variables.csv: P:", "1 to 9", "100000"]),
        "not_finite": (lines[:h] + ["h[1,0],nan\n"] + lines[h + 1:], ["variables.csv:9:", "h[1,0]", "nan"]),
    }
    for name, (content, expect) in sorted(cases.items()):
        os.makedirs(os.path.join(folder, name), exist_ok=True)
        with open(os.path.join(folder, name, "variables.csv"), "w") as f:
            f.write("".join(content))
        with open(os.path.join(folder, name + ".expect"), "w") as f:
            f.write("\n".join(expect) + "\n")


if __name__ == "__main__":
    main()
