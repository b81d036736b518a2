"""Makes `import slamrig` work from any folder: writes slamrig.pth (the build's python/ folder)
into the site-packages of this interpreter and of `python3` on PATH when that is another
interpreter of the same Python version (and of /usr/bin/python3 likewise), plus debian-numpy.pth (/usr/lib/python3/dist-packages)
where numpy is missing and Debian's is built for the same version."""

import os
import shutil
import subprocess
import sys

DEBIAN_DIST = "/usr/lib/python3/dist-packages"

SNIPPET = r"""
import importlib.util, os, site, sys, sysconfig
package_dir, debian = sys.argv[1], sys.argv[2]
target = sysconfig.get_paths()["purelib"]
if not os.access(target, os.W_OK):
    target = site.getusersitepackages()
os.makedirs(target, exist_ok=True)
written = []
with open(os.path.join(target, "slamrig.pth"), "w") as f:
    f.write(package_dir + "\n")
written.append("slamrig.pth")
debian_numpy = os.path.join(debian, "numpy")
if (importlib.util.find_spec("numpy") is None and os.path.isdir(debian_numpy)
        and any(n.endswith("-%d%d-x86_64-linux-gnu.so" % sys.version_info[:2]) or
                ("cpython-%d%d" % sys.version_info[:2]) in n
                for n in os.listdir(os.path.join(debian_numpy, "core")))):
    with open(os.path.join(target, "debian-numpy.pth"), "w") as f:
        f.write(debian + "\n")
    written.append("debian-numpy.pth")
print("%s: %s in %s" % (sys.executable, ", ".join(written), target))
"""


def install(python, package_dir):
    subprocess.run([python, "-c", SNIPPET, package_dir, DEBIAN_DIST], check=True)


def version(python):
    out = subprocess.run([python, "-c", "import sys; print(sys.version_info[:2])"],
                         capture_output=True, text=True, check=True)
    return out.stdout.strip()


def main():
    package_dir = os.path.abspath(sys.argv[1])
    install(sys.executable, package_dir)
    done = {os.path.realpath(sys.executable)}
    for other in (shutil.which("python3"), "/usr/bin/python3"):
        if not other or not os.access(other, os.X_OK):
            continue
        real = subprocess.run([other, "-c", "import sys; print(sys.executable)"],
                              capture_output=True, text=True).stdout.strip()
        if not real or os.path.realpath(real) in done:
            continue
        done.add(os.path.realpath(real))
        if version(other) == str(sys.version_info[:2]):
            install(other, package_dir)
        else:
            print("%s is Python %s; the module is built for %s (configure with "
                  "-DPython3_EXECUTABLE=%s to build for it)"
                  % (other, version(other), sys.version_info[:2], other))
    # The module must import where it was installed, from a neutral folder.
    subprocess.run([sys.executable, "-c", "import slamrig"], check=True, cwd="/")


if __name__ == "__main__":
    main()
