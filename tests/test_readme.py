#!/usr/bin/env python3
"""The README's commands run as printed.

usage: test_readme.py README BUILD_DIR SOURCE_DIR

The first ```sh block must be the two commands of a fresh machine (install and
build, run the tests); they exist and are executable but are not run here (the
second is what runs this test). Every later ```sh block runs with bash in a new
directory that looks like a clone after the first command (`build`, `data`,
`scripts`, `docs`, `python` link to the real ones), and must exit 0 and leave every file it names
after -o, --aov NAME=, --save-camera or --stats-json. With RR_TEST_QUICK set,
image sizes are divided by 4 (the sanitizer builds run them too)."""
import os
import re
import shlex
import subprocess
import sys
import tempfile


def sh_blocks(text):
    """The ```sh blocks, but those of the Library section: they install the package and
    build the C example against it, which test_install.sh does (in a scratch prefix)."""
    lib = re.search(r"^## Library\n.*?(?=^## |\Z)", text, re.S | re.M)
    return [m.group(1) for m in re.finditer(r"^```sh\n(.*?)^```", text, re.S | re.M)
            if not (lib and lib.start() <= m.start() < lib.end())]


def commands(block):
    """Commands of a block: continuation lines joined, comments and blanks dropped."""
    joined = block.replace("\\\n", " ")
    return [line.strip() for line in joined.splitlines() if line.strip() and not line.strip().startswith("#")]


def outputs(cmd):
    """Files a command promises to write."""
    try:
        words = shlex.split(cmd, comments=True)
    except ValueError:
        return []
    files = []
    for i, w in enumerate(words):
        nxt = words[i + 1] if i + 1 < len(words) else None
        if w in ("-o", "--output", "--save-camera", "--stats-json") and nxt:
            files.append(nxt)
        elif w.startswith(("--output=", "--save-camera=", "--stats-json=")):
            files.append(w.split("=", 1)[1])
        elif w == "--aov" and nxt and "=" in nxt:
            files.append(nxt.split("=", 1)[1])
        elif w.startswith("--aov=") and "=" in w[6:]:
            files.append(w[6:].split("=", 1)[1])
    return [f for f in files if f not in ("-", "/dev/null") and not f.startswith("/dev/")]


def quick(cmd):
    def smaller(m):
        return "--size %dx%d" % (max(8, int(m.group(1)) // 4), max(6, int(m.group(2)) // 4))
    return re.sub(r"--size[ =](\d+)x(\d+)", smaller, cmd)


def main():
    readme, build, source = sys.argv[1:4]
    text = open(readme, encoding="utf-8").read()
    blocks = sh_blocks(text)
    failures = []
    if not blocks:
        failures.append("no ```sh block in the README")
    else:
        first = [c.split()[0] for c in commands(blocks[0])]
        if first != ["scripts/demo.sh", "scripts/test.sh"]:
            failures.append("the first block must be scripts/demo.sh and scripts/test.sh, is %s" % first)
        for script in first:
            if not os.access(os.path.join(source, script), os.X_OK):
                failures.append("%s is not an executable file" % script)
    ran = 0
    for b, block in enumerate(blocks[1:], 2):
        cmds = commands(block)
        script = "\n".join(quick(c) if os.environ.get("RR_TEST_QUICK") else c for c in cmds)
        with tempfile.TemporaryDirectory() as clone:
            for name, target in (("build", build), ("data", os.path.join(source, "data")),
                                 ("scripts", os.path.join(source, "scripts")), ("docs", os.path.join(source, "docs")),
                                 ("python", os.path.join(source, "python"))):
                os.symlink(os.path.abspath(target), os.path.join(clone, name))
            # python3 is Debian's, as on a fresh machine (a python of one's own may
            # come first in PATH and lack NumPy)
            env = dict(os.environ, PATH="/usr/bin:" + os.environ.get("PATH", ""))
            # in the ASan/UBSan build the uninstrumented python3 loads an instrumented
            # librastray.so only with the sanitizer runtimes preloaded (CMakeLists.txt)
            if os.environ.get("RR_PYTHON_PRELOAD") and "python3" in script:
                env.update(LD_PRELOAD=os.environ["RR_PYTHON_PRELOAD"], ASAN_OPTIONS="detect_leaks=0")
            try:
                p = subprocess.run(["bash", "-euo", "pipefail", "-c", script], cwd=clone, capture_output=True,
                                   text=True, timeout=300, env=env)
            except subprocess.TimeoutExpired:
                failures.append("block %d ran over 300 s:\n%s" % (b, script))
                continue
            if p.returncode != 0:
                failures.append("block %d exited %d:\n%s\nstderr: %s" % (b, p.returncode, script, p.stderr[-2000:]))
                continue
            for c in cmds:
                for f in outputs(c):
                    path = os.path.join(clone, f)
                    if not (os.path.isfile(path) and os.path.getsize(path) > 0):
                        failures.append("block %d: '%s' did not write %s" % (b, c, f))
            ran += len(cmds)
    if ran == 0:
        failures.append("no command ran")
    for f in failures:
        print("FAIL:", f)
    print("%d README commands ran, %d failures" % (ran, len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
