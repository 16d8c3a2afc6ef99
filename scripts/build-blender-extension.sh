#!/usr/bin/env bash
# Builds the Blender extension (docs/blender.md) into target/blender/:
#   impulse-<version>.zip        the Blender 4.2+ extension: blender/ with the impulse wheel in
#                                wheels/ (Install from Disk, or `blender --command extension
#                                install-file`)
#   impulse-<version>-addon.zip  the same as a plain add-on: the wheel unpacked into vendor/
# The wheel is built with maturin through pip (a release build of crates/impulse-py), unless
# --wheel PATH gives one already built.
#
#   scripts/build-blender-extension.sh [--wheel PATH]
set -euo pipefail
cd "$(dirname "$0")/.."

wheel=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --wheel) wheel="$2"; shift 2 ;;
    *) echo "usage: $0 [--wheel PATH]" >&2; exit 2 ;;
  esac
done

version="$(sed -n 's/^version = "\(.*\)"$/\1/p' Cargo.toml | head -n 1)"
out=target/blender
mkdir -p "$out/wheels"
if [[ -z "$wheel" ]]; then
  nice python3 -m pip wheel --quiet --no-deps --disable-pip-version-check ./crates/impulse-py -w "$out/wheels"
  # The distribution is `impulse-contact` (the wheel impulse_contact-<version>-...); the
  # package it installs is `impulse`.
  wheel="$(ls -t "$out/wheels"/impulse_contact-"$version"-*.whl | head -n 1)"
fi
[[ -f "$wheel" ]] || { echo "error: no wheel at $wheel" >&2; exit 1; }

python3 - "$version" "$wheel" "$out" <<'PY'
import pathlib
import re
import shutil
import sys
import zipfile

version, wheel, out = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
source = pathlib.Path("blender")
# The wheel's platform tag as Blender's platform name.
tag = wheel.stem.split("-")[-1]
platforms = {"x86_64": "linux-x64", "aarch64": "linux-arm64"} if "linux" in tag else {}
if tag.startswith("macosx"):
    platforms = {"arm64": "macos-arm64", "x86_64": "macos-x64", "universal2": "macos-arm64"}
elif tag.startswith("win"):
    platforms = {"amd64": "windows-x64", "arm64": "windows-arm64"}
platform = next((name for arch, name in platforms.items() if tag.endswith(arch)), None)
if platform is None:
    sys.exit(f"error: no Blender platform for the wheel tag {tag}")

files = [p for p in sorted(source.rglob("*"))
         if p.is_file() and "__pycache__" not in p.parts and p.parts[1] not in ("tests", "vendor", "wheels")]

manifest = (source / "blender_manifest.toml").read_text()
manifest = re.sub(r'^version = ".*"$', f'version = "{version}"', manifest, count=1, flags=re.M)
manifest = re.sub(r"^platforms = \[.*\]$", f'platforms = ["{platform}"]', manifest, count=1, flags=re.M)
manifest = re.sub(r"^wheels = \[.*\]$", f'wheels = ["./wheels/{wheel.name}"]', manifest, count=1, flags=re.M)

extension = out / f"impulse-{version}.zip"
with zipfile.ZipFile(extension, "w", zipfile.ZIP_DEFLATED) as archive:
    for path in files:
        name = path.relative_to(source).as_posix()
        if name == "blender_manifest.toml":
            archive.writestr(name, manifest)
        else:
            archive.write(path, name)
    archive.write(wheel, f"wheels/{wheel.name}")

addon = out / f"impulse-{version}-addon.zip"
with zipfile.ZipFile(addon, "w", zipfile.ZIP_DEFLATED) as archive, zipfile.ZipFile(wheel) as packed:
    for path in files:
        name = path.relative_to(source).as_posix()
        if name != "blender_manifest.toml":
            archive.write(path, f"impulse_blender/{name}")
    for item in packed.infolist():
        if ".dist-info/" not in item.filename and not item.is_dir():
            archive.writestr(f"impulse_blender/vendor/{item.filename}", packed.read(item))
print(extension)
print(addon)
PY
