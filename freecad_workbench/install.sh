#!/usr/bin/env bash
# Install the tabletcad FreeCAD workbench into FreeCAD's user Mod folder.
#
#   bash freecad_workbench/install.sh             # symlink (edits in the repo are live)
#   bash freecad_workbench/install.sh --copy      # copy instead of symlink
#   bash freecad_workbench/install.sh --mod-dir DIR   # install into DIR (repeatable) instead
#   bash freecad_workbench/install.sh --macro-dir DIR # put the four macros into DIR
#   bash freecad_workbench/install.sh --uninstall     # remove the workbench and its macros
#
# The Mod folder is asked from FreeCAD itself (FreeCAD.getUserAppDataDir() + "Mod"), so the
# right place is used for Debian's 0.20 (~/.local/share/FreeCAD/Mod, or $FREECAD_USER_HOME/Mod),
# for 1.0 and for 1.1's versioned folders.  Without freecadcmd on PATH the usual candidates are
# used: $FREECAD_USER_HOME/Mod or ~/.local/share/FreeCAD/Mod, plus ~/.FreeCAD/Mod if it exists.
#
# The macro folder is FreeCAD's own (FreeCAD.getUserMacroDir(True)), else <Mod>/../Macro.
# $TABLETCAD_FREECADCMD, if set, is the command that runs FreeCADCmd (e.g. for FreeCAD 1.0 in
# the .ci/freecad1 root: ".ci/freecad1 run freecadcmd").
#
# Result: <Mod>/tabletcad_wb/freecad/tabletcad_wb  -> the namespace package freecad.tabletcad_wb
#         <Mod>/tabletcad_wb/tabletcad_core_path.txt  -> this repository (the tabletcad core)
#         <Macro>/tabletcad_*.FCMacro                 -> the four macros (linked or copied)
# No .pth file, nothing is installed into FreeCAD's or the system's Python.
set -euo pipefail
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
PKG="$REPO/freecad_workbench/freecad/tabletcad_wb"
MODE=link
UNINSTALL=0
DIRS=()
MACRO_DIR=""
while [ $# -gt 0 ]; do
  case "$1" in
    --copy) MODE=copy ;;
    --mod-dir) DIRS+=("$2"); shift ;;
    --macro-dir) MACRO_DIR="$2"; shift ;;
    --uninstall) UNINSTALL=1 ;;
    -h|--help) sed -n '2,25p' "$0"; exit 0 ;;
    *) echo "install.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done

freecad_cmd() {
  # FreeCAD's own Python, never the project's virtual environment
  if [ -n "${TABLETCAD_FREECADCMD:-}" ]; then echo "$TABLETCAD_FREECADCMD"; return; fi
  local p="${PATH}"
  if [ -n "${VIRTUAL_ENV:-}" ]; then p="$(echo "$PATH" | tr ':' '\n' | grep -v "^${VIRTUAL_ENV}/bin\$" | paste -sd: -)"; fi
  PATH="$p" command -v freecadcmd 2>/dev/null || PATH="$p" command -v FreeCADCmd 2>/dev/null || true
}

FC="$(freecad_cmd)"
ask=""
if [ -n "$FC" ] && { [ ${#DIRS[@]} -eq 0 ] || [ -z "$MACRO_DIR" ]; }; then
  # shellcheck disable=SC2086  # TABLETCAD_FREECADCMD may be a command with arguments
  ask="$(env -u VIRTUAL_ENV -u PYTHONPATH -u PYTHONHOME $FC -c \
    "import FreeCAD; print('TABLETCAD_MODDIR=' + FreeCAD.getUserAppDataDir()); print('TABLETCAD_MACRODIR=' + FreeCAD.getUserMacroDir(True))" 2>/dev/null || true)"
fi
if [ -z "$MACRO_DIR" ]; then MACRO_DIR="$(printf '%s\n' "$ask" | sed -n 's/^TABLETCAD_MACRODIR=//p' | tail -n 1)"; fi
if [ ${#DIRS[@]} -eq 0 ]; then
  data="$(printf '%s\n' "$ask" | sed -n 's/^TABLETCAD_MODDIR=//p' | tail -n 1)"
  if [ -n "$data" ]; then DIRS+=("${data%/}/Mod"); fi
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

# the four macros, beside the user's own
if [ -z "$MACRO_DIR" ]; then MACRO_DIR="$(dirname "${DIRS[0]%/}")/Macro"; fi
MACRO_DIR="${MACRO_DIR%/}"
for m in "$REPO"/freecad_workbench/macros/tabletcad_*.FCMacro; do
  rm -f "$MACRO_DIR/$(basename "$m")"
done
if [ "$UNINSTALL" = 1 ]; then
  echo "tabletcad macros: removed from $MACRO_DIR"
  exit 0
fi
mkdir -p "$MACRO_DIR"
for m in "$REPO"/freecad_workbench/macros/tabletcad_*.FCMacro; do
  if [ "$MODE" = copy ]; then cp "$m" "$MACRO_DIR/"; else ln -s "$m" "$MACRO_DIR/"; fi
done
echo "tabletcad macros: $(ls "$REPO"/freecad_workbench/macros/tabletcad_*.FCMacro | wc -l) installed ($MODE) in $MACRO_DIR"
