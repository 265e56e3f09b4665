#!/usr/bin/python3
"""Hostile-input campaign for `saltus`: generate every input, run it, classify the outcome.

    /usr/bin/python3 scripts/hostile/run.py [--saltus build/saltus] [--out report.md]
                                            [--only CATEGORY[,CATEGORY]] [--id REGEX] [--list]
                                            [--timeout 60] [--mem-gib 4] [--keep]

The cases (scripts/hostile/cases.py) are a fixed table of mutation rules over templates, with a
fixed seed for the random bytes, so every run generates the same inputs. Each case runs in a
fresh folder under a temporary root, one saltus process at a time, with a timeout and an
address-space limit (RLIMIT_AS) in the child. Outcomes:

  crash             killed by a signal the case did not send, or a sanitizer report, 'terminate
                    called', 'std::bad_alloc' or 'what():' on standard error
  timeout           still running after the timeout (or 20 s after SIGINT/SIGTERM)
  accepted-invalid  exit 0 on an input the case marks invalid
  refused-valid     non-zero exit on a valid control
  half-written      a refused command changed its folder (new, changed or removed files), or an
                    interrupted one left temporaries, frames, empty or partial files, or its own
                    outputs; or a second run after SIGKILL left the stale temporaries or empty
                    folders (SIGKILL cannot be handled: the killed run's leftovers are judged after it)
  check-failed      an extra check failed: /dev/null or /dev/stdout replaced, a symlink replaced,
                    processes left running after the command ended, exit 0 after an interruption,
                    the run after SIGKILL failed
  vague             refused, but the message does not name the option / the file and its line or
                    key / the path, or does not quote the value as written, or is a bare library
                    message ('Could not convert', 'stoi', ...)
  fixture-error     the campaign could not prepare the case (a fixture solve failed)
  refused-ok, accepted-ok, interrupted-ok   the right outcomes

SIGINT goes to the command's process group (as Ctrl-C does); SIGTERM and SIGKILL to the saltus
process alone (as `kill` and the OOM killer do). The report is markdown (summary table, failure
kinds, every case not OK); results.json beside it holds every case's details.
"""

import argparse
import collections
import hashlib
import json
import math
import os
import re
import resource
import shlex
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.dont_write_bytecode = True  # no __pycache__ beside the scripts
import cases as C  # noqa: E402
from yamlgen import dump  # noqa: E402

REPO = os.path.dirname(os.path.dirname(HERE))

BAD_OUTCOMES = ["crash", "timeout", "accepted-invalid", "refused-valid", "half-written", "check-failed", "vague",
                "fixture-error"]
OK_OUTCOMES = ["refused-ok", "accepted-ok", "interrupted-ok"]
OUTCOMES = BAD_OUTCOMES + OK_OUTCOMES

CRASH_PATTERNS = ["AddressSanitizer", "LeakSanitizer", "UndefinedBehaviorSanitizer", "runtime error:",
                  "terminate called", "std::bad_alloc", "what():", "Segmentation fault", "core dumped",
                  "Assertion `", "stack smashing"]
LIBRARY_MESSAGES = ["Could not convert", "bad_alloc", "Error document empty", "stoi", "stod", "stol", "stoul",
                    "basic_string", "_M_", "map::at", "bad_optional_access", "bad_variant_access",
                    "std::out_of_range", "std::invalid_argument", "std::runtime_error"]
GRACE = 20  # seconds a process gets to end after SIGINT / SIGTERM


# ----------------------------------------------------------------------------------------------
# Processes
# ----------------------------------------------------------------------------------------------

def _child_setup(mem_bytes):
    def f():
        resource.setrlimit(resource.RLIMIT_AS, (mem_bytes, mem_bytes))
        resource.setrlimit(resource.RLIMIT_CORE, (0, 0))
        # A campaign started from a background job inherits SIGINT ignored; the child must not.
        for s in (signal.SIGINT, signal.SIGTERM, signal.SIGPIPE, signal.SIGQUIT):
            signal.signal(s, signal.SIG_DFL)
    return f


def group_members(sid):
    """Live processes of the case's session (a step that moved to a process group of its own
    stays in the session), with their command lines."""
    pids = []
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            if int(fields[3]) == sid and fields[0] != "Z":
                with open(f"/proc/{entry}/cmdline", "rb") as f:
                    cmd = f.read().replace(b"\0", b" ").decode(errors="replace").strip()
                pids.append((int(entry), cmd[:200]))
        except (OSError, IndexError, ValueError):
            pass
    return pids


def reap_group(sid, wait=0.5):
    """Processes of the case's session still alive after the command ended; then kills them."""
    deadline = time.monotonic() + wait
    members = group_members(sid)
    while members and time.monotonic() < deadline:
        time.sleep(0.1)
        members = group_members(sid)
    for pid, _ in members:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    if members:
        time.sleep(0.2)
    return members


class Run:
    """One saltus process: exit status, the signal sent, timings, standard error."""

    @staticmethod
    def _spawn(argv, cwd, out, err, mem):
        # saltus may be mid-rebuild (another engineer works in the tree): wait for it up to 5 min
        for attempt in range(150):
            try:
                return subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=out, stderr=err,
                                        preexec_fn=_child_setup(mem), start_new_session=True)
            except (PermissionError, FileNotFoundError, OSError) as e:
                if attempt == 149 or (isinstance(e, OSError) and e.errno not in (1, 2, 13, 26)):
                    raise
                time.sleep(2)

    def __init__(self, argv, cwd, logbase, timeout, mem, sig=None, after=None):
        self.argv, self.sent, self.timed_out, self.early = argv, None, False, False
        t0 = time.monotonic()
        with open(logbase + ".out", "wb") as out, open(logbase + ".err", "wb") as err:
            p = self._spawn(argv, cwd, out, err, mem)
            try:
                if sig:
                    try:
                        p.wait(timeout=after)
                        self.early = True
                    except subprocess.TimeoutExpired:
                        s = getattr(signal, sig)
                        if s == signal.SIGINT:
                            os.killpg(p.pid, s)
                        else:
                            p.send_signal(s)
                        self.sent = s
                        p.wait(timeout=GRACE if s != signal.SIGKILL else 10)
                else:
                    p.wait(timeout=timeout)
            except subprocess.TimeoutExpired:
                self.timed_out = True
                for pid, _ in group_members(p.pid) or [(p.pid, "")]:
                    try:
                        os.kill(pid, signal.SIGKILL)
                    except ProcessLookupError:
                        pass
                p.wait()
        self.rc = p.returncode
        self.seconds = time.monotonic() - t0
        self.orphans = reap_group(p.pid)
        with open(logbase + ".err", "rb") as f:
            data = f.read(1 << 20)
        self.err = data.decode(errors="replace")
        lines = [l.strip() for l in self.err.splitlines() if l.strip()]
        self.first = lines[0][:300] if lines else ""


# ----------------------------------------------------------------------------------------------
# Files
# ----------------------------------------------------------------------------------------------

def make_fixtures(root, needed, saltus, mem, log):
    os.makedirs(root, exist_ok=True)
    status = {}
    for name in sorted(needed):
        path = os.path.join(root, name)
        try:
            if name == "traj.csv":
                open(path, "w").write(C.ball_drop_csv())
            elif name == "long.csv":
                open(path, "w").write(C.long_csv())
            elif name == "sol_drop":
                r = Run([saltus, "optimize", "point_mass_drop", "--out", name], root, path + ".log", 300, mem)
                if r.rc != 0:
                    raise RuntimeError(f"optimize point_mass_drop exited {r.rc}: {r.first}")
            elif name == "sol_push":
                open(os.path.join(root, "push.yaml"), "w").write(dump(C.PROBLEM))
                r = Run([saltus, "optimize", "push.yaml", "--out", name], root, path + ".log", 300, mem)
                if r.rc != 0:
                    raise RuntimeError(f"optimize of the problem template exited {r.rc}: {r.first}")
            else:
                raise RuntimeError(f"unknown fixture {name}")
            status[name] = None
        except Exception as e:  # the cases that need it report fixture-error
            status[name] = str(e)
            log(f"fixture {name}: {e}")
    return status


def materialise(case, d, fixtures_dir):
    os.makedirs(d)
    items = list(case["files"].items())
    order = [kv for kv in items if isinstance(kv[1], tuple) and kv[1][0] == "fixture"]
    rest = [kv for kv in items if kv not in order]
    for name, content in order:
        src, dst = os.path.join(fixtures_dir, content[1]), os.path.join(d, name)
        os.makedirs(os.path.dirname(dst), exist_ok=True)
        if os.path.isdir(src):
            shutil.copytree(src, dst, symlinks=True)
        else:
            shutil.copy2(src, dst)
    for rel in case["remove"]:
        p = os.path.join(d, rel)
        if os.path.lexists(p):
            os.remove(p)
    for name, content in rest:
        p = os.path.join(d, name)
        os.makedirs(os.path.dirname(p), exist_ok=True)
        if isinstance(content, str):
            with open(p, "w", encoding="utf-8", newline="") as f:
                f.write(content)
        elif isinstance(content, bytes):
            with open(p, "wb") as f:
                f.write(content)
        elif content[0] == "dir":
            os.makedirs(p, exist_ok=True)
        elif content[0] == "symlink":
            os.symlink(content[1], p)
        elif content[0] == "fifo":
            os.mkfifo(p)
        elif content[0] == "derive":
            with open(os.path.join(fixtures_dir, content[1]), "rb") as f:
                data = content[2](f.read())
            if os.path.lexists(p):
                os.remove(p)
            with open(p, "wb") as f:
                f.write(data)
        else:
            raise ValueError(content)


def _digest(path, size):
    h = hashlib.sha1()
    with open(path, "rb") as f:
        if size <= 64 << 20:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        else:
            h.update(f.read(1 << 20))
            f.seek(-(1 << 20), 2)
            h.update(f.read())
    return h.hexdigest()


def snapshot(d):
    snap = {}
    for dirpath, dirnames, filenames in os.walk(d):
        for name in dirnames + filenames:
            p = os.path.join(dirpath, name)
            rel = os.path.relpath(p, d)
            try:
                st = os.lstat(p)
            except OSError:
                continue
            if stat.S_ISLNK(st.st_mode):
                snap[rel] = ("link", os.readlink(p))
            elif stat.S_ISDIR(st.st_mode):
                snap[rel] = ("dir",)
            elif stat.S_ISREG(st.st_mode):
                snap[rel] = ("file", st.st_size, _digest(p, st.st_size))
            else:
                snap[rel] = ("other", stat.S_IFMT(st.st_mode))
    return snap


def diff(before, after):
    added = sorted(set(after) - set(before))
    removed = sorted(set(before) - set(after))
    modified = sorted(k for k in set(before) & set(after) if before[k] != after[k])
    return added, removed, modified


def incomplete(d, rel, info):
    """Why a file left by an interrupted command is not a complete output, or None."""
    if any(".tmp" in part for part in rel.split(os.sep)):
        return "temporary left behind"
    p = os.path.join(d, rel)
    if info[0] == "dir":
        try:
            return "empty folder left behind" if not os.listdir(p) else None
        except OSError:
            return None
    if info[0] != "file":
        return None
    if info[1] == 0:
        if os.path.basename(rel) == ".lock":
            return None  # a lock file (flock), left by every sweep, also a successful one
        return "empty file"
    if re.search(r"frame_\d+\.png$", rel):
        return "frame of an interrupted render"
    try:
        if rel.endswith(".csv"):
            text = open(p, "rb").read(256 << 20).decode(errors="replace")
            if not text.endswith("\n"):
                return "partial CSV (no newline after the last row)"
            rows = [l for l in text.splitlines() if l and not l.startswith("#")]
            if os.path.basename(rel) == "variables.csv":  # name,value with commas inside names: h[1,0]
                for l in rows[1:]:
                    try:
                        float(l.rsplit(",", 1)[1])
                    except (IndexError, ValueError):
                        return "partial CSV (a row without a value)"
            elif len({l.count(",") for l in rows}) > 1:
                return "partial CSV (rows of different lengths)"
        elif rel.endswith(".json"):
            json.load(open(p))
        elif rel.endswith(".png"):
            with open(p, "rb") as f:
                f.seek(-12, 2)
                if f.read()[4:8] != b"IEND":
                    return "partial PNG (no IEND chunk)"
        elif rel.endswith(".mp4"):
            if b"moov" not in open(p, "rb").read():
                return "partial MP4 (no moov atom)"
    except (ValueError, OSError) as e:
        return f"unreadable or partial ({e.__class__.__name__})"
    return None


# ----------------------------------------------------------------------------------------------
# Devices the campaign targets on purpose (it runs as root: a rename onto them would replace them)
# ----------------------------------------------------------------------------------------------

DEVICES = {"/dev/null": (1, 3), "/dev/full": (1, 7)}


def device_state():
    state = {}
    for p in DEVICES:
        try:
            st = os.lstat(p)
            state[p] = (stat.S_ISCHR(st.st_mode), st.st_rdev)
        except OSError:
            state[p] = None
    state["/dev/stdout"] = os.readlink("/dev/stdout") if os.path.islink("/dev/stdout") else None
    return state


def restore_devices(before):
    broken = []
    for p, (major, minor) in DEVICES.items():
        try:
            st = os.lstat(p)
            ok = stat.S_ISCHR(st.st_mode) and st.st_rdev == os.makedev(major, minor)
        except OSError:
            ok = False
        if not ok and before.get(p) and before[p][0]:
            broken.append(p)
            if os.path.lexists(p):
                if os.path.isdir(p) and not os.path.islink(p):
                    shutil.rmtree(p)
                else:
                    os.remove(p)
            os.mknod(p, 0o666 | stat.S_IFCHR, os.makedev(major, minor))
            os.chmod(p, 0o666)
    if before.get("/dev/stdout") and not (os.path.islink("/dev/stdout")
                                          and os.readlink("/dev/stdout") == before["/dev/stdout"]):
        broken.append("/dev/stdout")
        if os.path.lexists("/dev/stdout"):
            if os.path.isdir("/dev/stdout") and not os.path.islink("/dev/stdout"):
                shutil.rmtree("/dev/stdout")
            else:
                os.remove("/dev/stdout")
        os.symlink(before["/dev/stdout"], "/dev/stdout")
    return broken


# ----------------------------------------------------------------------------------------------
# Classification
# ----------------------------------------------------------------------------------------------

NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def same_number(value, msg):
    """A finite number written as `value` appears in msg reformatted ('-1' as '-1.000000', '1e300' as
    '1e+300'). A value the conversion changed does not count: 1e400 shown as inf, 1e-400 as 0."""
    if not NUMBER.fullmatch(value.strip()):
        return False
    x = float(value)
    if not math.isfinite(x) or (x == 0 and re.search(r"[1-9]", value)):
        return False
    return any(float(m.group()) == x for m in NUMBER.finditer(msg))


def quoted(value, msg):
    """value appears in msg as a token: '1e400' is not quoted by '1e4000', nor 'nan' by 'nanometre',
    nor '2' by '2.5'; a size as WIDTHxHEIGHT ('0x64', '64x-1') quotes both numbers; a finite number
    may be reformatted (same_number)."""
    if same_number(value, msg):
        return True
    low, v = msg.lower(), value.lower()
    word = lambda ch: ch.isalnum() or ch == "_"
    start = low.find(v)
    while start >= 0:
        end = start + len(v)
        before = low[start - 1] if start else " "
        before2 = low[start - 2] if start > 1 else " "
        after = low[end] if end < len(low) else " "
        after2 = low[end + 1] if end + 1 < len(low) else " "
        left = not word(before) and not (before == "." and before2.isdigit()) or (before == "x" and before2.isdigit())
        right = not word(after) and not (after == "." and after2.isdigit()) or (after == "x" and (after2.isdigit() or after2 == "-"))
        if left and right:
            return True
        start = low.find(v, start + 1)
    return False


def located(case, msg):
    """Reasons the refusal message does not say where and what (empty: it does)."""
    reasons = []
    if not msg.strip():
        return ["no message on standard error"]
    for lib in LIBRARY_MESSAGES:
        if lib in msg:
            reasons.append(f"bare library message ('{lib}')")
    alts = case["expect"] or []
    if isinstance(alts, dict):
        alts = [alts]
    best = None
    for alt in alts:
        miss = []
        if "option" in alt and alt["option"] not in msg:
            miss.append(f"does not name the option {alt['option']}")
        if "path" in alt and alt["path"] not in msg:
            miss.append("does not name the path")
        if "file" in alt:
            name = alt["file"]
            if name not in msg:
                miss.append("does not name the file")
            else:
                line = re.search(re.escape(name) + r":\d+", msg) or re.search(r"\bline \d+", msg)
                key = any(k and quoted(k, msg) for k in alt.get("keys", [])) or (
                    alt.get("key_re") and re.search(alt["key_re"], msg))
                if not (line or key):
                    miss.append("names the file but neither a line nor the key")
        if best is None or len(miss) < len(best):
            best = miss
    reasons += best or []
    if case.get("value") and not any(quoted(v, msg) for v in case["value"] if v):
        reasons.append("does not quote the value as written")
    return reasons


def judge_interrupted(case, d, run, before, after):
    """Problems with what an interrupted command left (judged before any second run)."""
    problems = []
    killed = run.sent == signal.SIGKILL
    added, removed, modified = diff(before, after)
    absent = case["absent"]
    under = lambda rel: any(rel == a or rel.startswith(a + "/") for a in absent)
    for rel in added + (modified if case.get("may_remove") else []):
        why = incomplete(d, rel, after[rel])
        if under(rel) and after[rel][0] != "dir":
            why = "output of the interrupted command"
        if why in ("temporary left behind", "empty folder left behind") and killed:
            # SIGKILL cannot be handled: what the killed process had made (a temporary, a step
            # folder it had just created) is judged after the second run, which must remove it
            continue
        if why:
            problems.append({"outcome": "half-written", "reason": why, "detail": rel})
    if not case.get("may_remove"):
        for rel in modified:
            problems.append({"outcome": "half-written", "reason": "an earlier output was changed", "detail": rel})
        for rel in removed:
            problems.append({"outcome": "half-written", "reason": "an earlier output was removed", "detail": rel})
    return problems


def classify(case, d, run, before, after, follow, after2, broken_devices, symlinks_before, interrupted):
    problems = []

    def prob(outcome, reason, detail=""):
        problems.append({"outcome": outcome, "reason": reason, "detail": detail})

    sig = case.get("signal")
    if run.rc is not None and run.rc < 0 and not run.timed_out and not (run.sent and -run.rc == run.sent):
        prob("crash", f"killed by {signal.Signals(-run.rc).name}")
    for pat in CRASH_PATTERNS:
        if pat in run.err:
            prob("crash", f"'{pat}' on standard error")
    if run.timed_out:
        prob("timeout", "still running after the timeout" if not run.sent
             else f"still running {GRACE} s after {signal.Signals(run.sent).name}")
    if run.orphans:
        prob("check-failed", "processes left running after the command ended",
             "; ".join(f"{pid} {cmd}" for pid, cmd in run.orphans))
    for dev in broken_devices:
        prob("check-failed", f"{dev} was replaced (restored by the campaign)")
    for c in case["checks"]:
        if c.startswith("symlink:"):
            name = c.split(":", 1)[1]
            p = os.path.join(d, name)
            if not os.path.islink(p) or os.readlink(p) != symlinks_before.get(name):
                prob("check-failed", "the --out symlink was replaced", name)

    added, removed, modified = diff(before, after)
    crashed = any(p["outcome"] == "crash" for p in problems) or run.timed_out

    if sig:
        if run.early:
            prob("check-failed", "ended before the signal was sent (the case is too short)", f"exit {run.rc}")
        elif run.rc == 0:
            prob("check-failed", "exit status 0 after an interruption")
        problems += interrupted
        if follow is not None:
            if follow.rc != 0:
                prob("check-failed", "the run after SIGKILL failed", f"exit {follow.rc}: {follow.first}")
            stale = [rel for rel in after2 if any(".tmp" in part for part in rel.split(os.sep))]
            for rel in stale:
                prob("half-written", "stale temporary not removed by a second run", rel)
            for rel in after2:
                if after2[rel][0] == "dir" and incomplete(d, rel, after2[rel]) == "empty folder left behind":
                    prob("half-written", "empty folder not removed by a second run", rel)
            for p in ("crash",):
                if follow.rc is not None and follow.rc < 0:
                    prob(p, f"second run killed by {signal.Signals(-follow.rc).name}")
    else:
        if run.rc == 0:
            if case["valid"] is False:
                prob("accepted-invalid", "exit 0 on an invalid input")
            for rel in added:
                if any(".tmp" in part for part in rel.split(os.sep)):
                    prob("half-written", "temporary left behind after success", rel)
        elif run.rc is not None:
            if case["valid"] is True and not crashed:
                prob("refused-valid", "a valid control was refused", run.first)
            for rel in added:
                kind = after[rel][0]
                prob("half-written", "refused, yet created " + ("a folder" if kind == "dir" else "a file"), rel)
            for rel in modified:
                prob("half-written", "refused, yet changed a file", rel)
            for rel in removed:
                prob("half-written", "refused, yet removed a file", rel)
            if run.rc > 0 and case["valid"] is not True:
                for r in located(case, run.err):
                    prob("vague", r)

    outcome = None
    for o in BAD_OUTCOMES:
        if any(p["outcome"] == o for p in problems):
            outcome = o
            break
    if outcome is None:
        outcome = "interrupted-ok" if sig else ("accepted-ok" if run.rc == 0 else "refused-ok")
    return outcome, problems


# ----------------------------------------------------------------------------------------------
# Running a case
# ----------------------------------------------------------------------------------------------

def show(cmd):
    def arg(a):
        a = a if len(a) <= 80 else a[:40] + f"...({len(a)} chars)"
        return shlex.quote(a)
    return " ".join(["saltus"] + [arg(a) for a in cmd])


def run_case(case, root, saltus, args, fixture_status):
    d = os.path.join(root, "cases", case["id"])
    logs = os.path.join(root, "logs")
    res = {k: case.get(k) for k in ("id", "cat", "desc", "valid", "expect", "value", "signal", "after", "checks",
                                    "absent")}
    res["cmd"] = show(case["cmd"])
    res["followup"] = show(case["followup"]) if case.get("followup") else None
    missing = [f for f in case["fixtures"] if fixture_status.get(f)]
    if missing:
        res.update(outcome="fixture-error", problems=[{"outcome": "fixture-error", "reason": "fixture failed",
                                                        "detail": fixture_status[missing[0]]}], rc=None,
                   stderr_first="", seconds=0)
        return res
    materialise(case, d, os.path.join(root, "fixtures"))
    for k, p in enumerate(case["prep"]):
        r = Run([saltus] + p, d, os.path.join(logs, f"{case['id']}.prep{k}"), args.timeout, args.mem)
        if r.rc != 0:
            res.update(outcome="fixture-error", rc=None, stderr_first=r.first, seconds=0,
                       problems=[{"outcome": "fixture-error", "reason": "preparation failed",
                                  "detail": f"{show(p)} exited {r.rc}: {r.first}"}])
            return res
    for name, content in (case.get("post_prep") or {}).items():
        p = os.path.join(d, name)
        if content is None:
            os.remove(p)
        else:
            with open(p, "w") as f:
                f.write(content)
    before = snapshot(d)
    symlinks = {c.split(":", 1)[1]: os.readlink(os.path.join(d, c.split(":", 1)[1]))
                for c in case["checks"] if c.startswith("symlink:")}
    dev_before = device_state()
    run = Run([saltus] + case["cmd"], d, os.path.join(logs, case["id"]), case.get("timeout") or args.timeout,
              args.mem, case.get("signal"), case.get("after"))
    broken = restore_devices(dev_before)
    after = snapshot(d)
    interrupted = judge_interrupted(case, d, run, before, after) if case.get("signal") else []
    follow = after2 = None
    if case.get("followup"):
        follow = Run([saltus] + case["followup"], d, os.path.join(logs, case["id"] + ".followup"), args.timeout,
                     args.mem)
        broken += restore_devices(dev_before)
        after2 = snapshot(d)
    outcome, problems = classify(case, d, run, before, after, follow, after2, broken, symlinks, interrupted)
    added, removed, modified = diff(before, after)
    res.update(outcome=outcome, problems=problems, rc=run.rc, seconds=round(run.seconds, 3),
               signal_sent=signal.Signals(run.sent).name if run.sent else None, stderr_first=run.first,
               stderr=run.err[:800], added=added[:50], removed=removed[:50], modified=modified[:50],
               followup_rc=follow.rc if follow else None)
    if not args.keep:
        shutil.rmtree(d, ignore_errors=True)
    return res


# ----------------------------------------------------------------------------------------------
# Report
# ----------------------------------------------------------------------------------------------

def md(s):
    return str(s).replace("|", "\\|").replace("\n", " ").replace("`", "'")


def where_of(r):
    """The subcommand a case runs ('bench work-precision' for the bench ones)."""
    words = r["cmd"].split()[1:3]
    return " ".join(words) if words and words[0] == "bench" else (words[0] if words else "(none)")


def kind_of(r):
    """The failure kind a non-OK case is grouped under: its outcome and the reason(s)."""
    reasons = sorted({p["reason"] for p in r["problems"] if p["outcome"] == r["outcome"]})
    if r["outcome"] == "half-written" and len(reasons) > 1:
        reasons = [reasons[0] + " (and more)"]
    return f"{r['outcome']}: {'; '.join(reasons)}"


def summarise(problems):
    """'reason (detail)' per reason, with a count and the first detail where one repeats."""
    by_reason = collections.OrderedDict()
    for p in problems:
        if p["outcome"] in BAD_OUTCOMES:
            by_reason.setdefault(p["reason"], []).append(p["detail"])
    parts = []
    for reason, details in by_reason.items():
        details = [x for x in details if x]
        n = f" x{len(details)}" if len(details) > 1 else ""
        parts.append(reason + (f"{n} ({details[0][:120]}{', ...' if n else ''})" if details else ""))
    return "; ".join(parts)


def write_report(results, path, meta):
    by_cat = collections.defaultdict(collections.Counter)
    for r in results:
        by_cat[r["cat"]][r["outcome"]] += 1
    cats = [c for c in C.CATEGORIES if c in by_cat]
    cols = [o for o in OUTCOMES if any(by_cat[c][o] for c in cats)]
    L = ["# Hostile-input campaign", ""]
    L += [f"- saltus: `{meta['saltus']}` ({meta['version']}, modified {meta['mtime']})",
          f"- {len(results)} cases ({meta['valid']} valid controls, {meta['either']} either-way, "
          f"{meta['invalid']} invalid), seed {C.SEED}, timeout {meta['timeout']} s, address space {meta['mem_gib']} GiB",
          f"- started {meta['started']}, {meta['minutes']:.1f} min; rerun: `/usr/bin/python3 scripts/hostile/run.py`"
          " (one case: `--id ID --keep`, files kept under the temporary root)",
          f"- not OK: **{sum(1 for r in results if r['outcome'] in BAD_OUTCOMES)}** of {len(results)}"]
    if meta.get("rebuilt"):
        L.append("- **saltus was rebuilt while the campaign ran**: cases ran against more than one build")
    L += ["", "Outcomes: " + "; ".join(f"`{o}`" for o in OUTCOMES) + " (definitions: `scripts/hostile/run.py`).", ""]
    L += ["## Summary", "", "| category | " + " | ".join(cols) + " | total |",
          "| --- | " + " | ".join("---:" for _ in cols) + " | ---: |"]
    for c in cats:
        L.append(f"| {c} | " + " | ".join(str(by_cat[c][o] or "") for o in cols) + f" | {sum(by_cat[c].values())} |")
    tot = collections.Counter(r["outcome"] for r in results)
    L.append("| **total** | " + " | ".join(f"**{tot[o]}**" for o in cols) + f" | **{len(results)}** |")
    L.append("")
    bad = [r for r in results if r["outcome"] in BAD_OUTCOMES]
    groups = collections.OrderedDict()
    for r in sorted(bad, key=lambda r: (BAD_OUTCOMES.index(r["outcome"]), kind_of(r))):
        groups.setdefault(kind_of(r), []).append(r)
    L += ["## Failure kinds", "", "Grouped by outcome and reason; 'where' counts the cases per category / subcommand.", "",
          "| kind | cases | where | example | command | first line of stderr |",
          "| --- | ---: | --- | --- | --- | --- |"]
    for k, rs in groups.items():
        e = rs[0]
        where = collections.Counter(f"{r['cat']}/{where_of(r)}" for r in rs)
        w = ", ".join(f"{n} {c}" for c, n in where.most_common())
        L.append(f"| {md(k)} | {len(rs)} | {md(w)} | {md(e['id'])} | `{md(e['cmd'])}` | {md(e['stderr_first'][:200])} |")
    L.append("")
    L += ["## Cases not OK", ""]
    for c in cats:
        rs = [r for r in bad if r["cat"] == c]
        if not rs:
            continue
        L += [f"### {c} ({len(rs)})", "", "| id | outcome | description | exit | first line of stderr | why |",
              "| --- | --- | --- | ---: | --- | --- |"]
        for r in rs:
            why = summarise(r["problems"])
            L.append(f"| {md(r['id'])} | {r['outcome']} | {md(r['desc'])} | {r['rc']} | "
                     f"{md(r['stderr_first'][:200])} | {md(why[:400])} |")
        L.append("")
    with open(path, "w") as f:
        f.write("\n".join(L) + "\n")


# ----------------------------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--saltus", default=os.path.join(REPO, "build", "saltus"))
    ap.add_argument("--out", default=os.path.join(HERE, "report.md"), help="markdown report (results.json beside it)")
    ap.add_argument("--only", help="categories, comma-separated: " + ", ".join(C.CATEGORIES))
    ap.add_argument("--id", help="only the cases whose id matches this regular expression")
    ap.add_argument("--list", action="store_true", help="list the cases and stop")
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("--mem-gib", type=float, default=4)
    ap.add_argument("--keep", action="store_true", help="keep every case's folder")
    args = ap.parse_args()
    args.mem = int(args.mem_gib * (1 << 30))

    cases = C.build()
    if args.only:
        want = set(args.only.split(","))
        unknown = want - set(C.CATEGORIES)
        if unknown:
            ap.error(f"--only: unknown categories {', '.join(sorted(unknown))} (known: {', '.join(C.CATEGORIES)})")
        cases = [c for c in cases if c["cat"] in want]
    if args.id:
        cases = [c for c in cases if re.search(args.id, c["id"])]
    if args.list:
        for c in cases:
            v = {True: "valid", False: "invalid", "either": "either"}[c["valid"]]
            sig = f" [{c['signal']} after {c['after']} s]" if c.get("signal") else ""
            print(f"{c['id']}\t{c['cat']}\t{v}\t{show(c['cmd'])}{sig}\t{c['desc']}")
        print(f"{len(cases)} cases", file=sys.stderr)
        return 0
    saltus = os.path.abspath(args.saltus)
    if not os.access(saltus, os.X_OK):
        ap.error(f"--saltus: {saltus} is not an executable")

    root = tempfile.mkdtemp(prefix="saltus-hostile-")
    os.makedirs(os.path.join(root, "logs"))
    log = lambda s: print(s, file=sys.stderr, flush=True)
    log(f"hostile: {len(cases)} cases, root {root}")
    started = time.strftime("%Y-%m-%d %H:%M:%S")
    mtime0 = os.path.getmtime(saltus)
    t0 = time.monotonic()
    needed = {f for c in cases for f in c["fixtures"]}
    fixture_status = make_fixtures(os.path.join(root, "fixtures"), needed, saltus, args.mem, log)
    results = []
    try:
        for k, case in enumerate(cases, 1):
            try:
                r = run_case(case, root, saltus, args, fixture_status)
            except Exception as e:  # an error of the campaign itself: reported, the campaign goes on
                r = {k: case.get(k) for k in ("id", "cat", "desc", "valid", "expect", "value", "signal")}
                r.update(cmd=show(case["cmd"]), outcome="fixture-error", rc=None, seconds=0, stderr_first="",
                         problems=[{"outcome": "fixture-error", "reason": "campaign error",
                                    "detail": f"{e.__class__.__name__}: {e}"}])
            results.append(r)
            log(f"[{k}/{len(cases)}] {case['id']}: {r['outcome']} (exit {r['rc']}, {r['seconds']:.2f} s)"
                + ("" if r["outcome"] in OK_OUTCOMES else f"  {r['stderr_first'][:120]}"))
    except KeyboardInterrupt:
        log("hostile: interrupted; writing the report of the cases so far")
    try:
        version = subprocess.run([saltus, "--version"], capture_output=True, text=True, timeout=10).stdout.strip()
    except Exception:
        version = "?"
    meta = dict(saltus=saltus, version=version or "?", started=started, timeout=args.timeout, mem_gib=args.mem_gib,
                mtime=time.strftime("%Y-%m-%d %H:%M:%S", time.localtime(mtime0)),
                rebuilt=os.path.exists(saltus) and os.path.getmtime(saltus) != mtime0,
                minutes=(time.monotonic() - t0) / 60,
                valid=sum(1 for r in results if r["valid"] is True),
                either=sum(1 for r in results if r["valid"] == "either"),
                invalid=sum(1 for r in results if r["valid"] is False))
    os.makedirs(os.path.dirname(os.path.abspath(args.out)), exist_ok=True)
    write_report(results, args.out, meta)
    jpath = os.path.join(os.path.dirname(os.path.abspath(args.out)), "results.json")
    with open(jpath, "w") as f:
        json.dump({"meta": meta, "results": results}, f, indent=1, default=str)
    counts = collections.Counter(r["outcome"] for r in results)
    log("hostile: " + ", ".join(f"{o} {counts[o]}" for o in OUTCOMES if counts[o]))
    log(f"hostile: wrote {args.out} and {jpath}" + (f"; case folders kept in {root}" if args.keep else ""))
    if not args.keep:
        shutil.rmtree(root, ignore_errors=True)
    return 1 if any(r["outcome"] in BAD_OUTCOMES for r in results) else 0


if __name__ == "__main__":
    sys.exit(main())
