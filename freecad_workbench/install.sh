#!/usr/bin/env bash
# Install the tabletcad FreeCAD workbench into FreeCAD's user Mod folder.
#
#   bash freecad_workbench/install.sh             # symlink (edits in the repo are live)
#   bash freecad_workbench/install.sh --copy      # copy instead of symlink
#   bash freecad_workbench/install.sh --mod-dir DIR   # install into DIR (repeatable) instead
#   bash freecad_workbench/install.sh --uninstall
#
# The Mod folder is asked from FreeCAD itself (FreeCAD.getUserAppDataDir() + "Mod"), so the
# right place is used for Debian's 0.20 (~/.local/share/FreeCAD/Mod, or $FREECAD_USER_HOME/Mod),
# for 1.0 and for 1.1's versioned folders.  Without freecadcmd on PATH the usual candidates are
# used: $FREECAD_USER_HOME/Mod or ~/.local/share/FreeCAD/Mod, plus ~/.FreeCAD/Mod if it exists.
#
# Result: <Mod>/tabletcad_wb/freecad/tabletcad_wb  -> the namespace package freecad.tabletcad_wb
#         <Mod>/tabletcad_wb/tabletcad_core_path.txt  -> this repository (the tabletcad core)
# No .pth file, nothing is installed into FreeCAD's or the system's Python.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PKG="$REPO/freecad_workbench/freecad/tabletcad_wb"
MODE=link
UNINSTALL=0
DIRS=()
while [ $# -gt 0 ]; do
  case "$1" in
    --copy) MODE=copy ;;
    --mod-dir) DIRS+=("$2"); shift ;;
    --uninstall) UNINSTALL=1 ;;
    -h|--help) sed -n '2,18p' "$0"; exit 0 ;;
    *) echo "install.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done

freecad_cmd() {
  # FreeCAD's own Python, never the project's virtual environment
  local p="${PATH}"
  if [ -n "${VIRTUAL_ENV:-}" ]; then p="$(echo "$PATH" | tr ':' '\n' | grep -v "^${VIRTUAL_ENV}/bin\$" | paste -sd: -)"; fi
  PATH="$p" command -v freecadcmd 2>/dev/null || PATH="$p" command -v FreeCADCmd 2>/dev/null || true
}

if [ ${#DIRS[@]} -eq 0 ]; then
  FC="$(freecad_cmd)"
  if [ -n "$FC" ]; then
    data="$(env -u VIRTUAL_ENV -u PYTHONPATH -u PYTHONHOME "$FC" -c \
      "import FreeCAD; print('TABLETCAD_MODDIR=' + FreeCAD.getUserAppDataDir())" 2>/dev/null \
      | sed -n 's/^TABLETCAD_MODDIR=//p' | tail -n 1)"
    if [ -n "$data" ]; then DIRS+=("${data%/}/Mod"); fi
  fi
  if [ ${#DIRS[@]} -eq 0 ]; then
    if [ -n "${FREECAD_USER_HOME:-}" ]; then DIRS+=("$FREECAD_USER_HOME/Mod")
    else DIRS+=("${XDG_DATA_HOME:-$HOME/.local/share}/FreeCAD/Mod"); fi
    if [ -d "$HOME/.FreeCAD/Mod" ]; then DIRS+=("$HOME/.FreeCAD/Mod"); fi
  fi
fi

for mod in "${DIRS[@]}"; do
  dest="$mod/tabletcad_wb"
  if [ -L "$dest/freecad/tabletcad_wb" ] || [ -e "$dest/freecad/tabletcad_wb" ] || [ -e "$dest/tabletcad_core_path.txt" ]; then
    rm -rf "$dest/freecad/tabletcad_wb" "$dest/tabletcad_core_path.txt"
    rmdir "$dest/freecad" "$dest" 2>/dev/null || true
  fi
  if [ "$UNINSTALL" = 1 ]; then echo "tabletcad workbench: removed from $mod"; continue; fi
  mkdir -p "$dest/freecad"
  if [ "$MODE" = copy ]; then
    cp -r "$PKG" "$dest/freecad/tabletcad_wb"
    find "$dest/freecad/tabletcad_wb" -name __pycache__ -prune -exec rm -rf {} +
  else
    ln -s "$PKG" "$dest/freecad/tabletcad_wb"
  fi
  printf '%s\n' "$REPO" > "$dest/tabletcad_core_path.txt"
  echo "tabletcad workbench: installed ($MODE) into $dest (core: $REPO)"
done
