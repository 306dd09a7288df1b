#!/bin/sh
# The Python package is built for one interpreter (CMake's ATMOS_PYTHON_EXE, the system's
# python3 unless -DATMOS_PYTHON says otherwise; docs/python.md). Imported by an interpreter
# without NumPy or the compiled module (another python3 first on PATH: pyenv, a venv), the
# ImportError says which interpreter the build was for and what is missing, not only
# "No module named 'numpy'". An interpreter without its site-packages (python -S) stands in
# for one without NumPy.
. "$(dirname "$0")/common.inc"
src=${ATMOS_SOURCE_DIR:?ATMOS_SOURCE_DIR not set}

py=/usr/bin/python3
[ -x "$py" ] || py=$(command -v python3)
PYTHONPATH="$src/python" PYTHONDONTWRITEBYTECODE=1 "$py" -S -c 'import atmos' >/dev/null 2>"$T/err"
[ $? -ne 0 ] && ok "import without NumPy fails" || bad "import atmos worked without site-packages"
msg=$(tail -n 1 "$T/err")
echo "$msg" | grep -q "ImportError" && ok "an ImportError" || bad "not an ImportError: $msg"
echo "$msg" | grep -q "numpy" && ok "names numpy" || bad "does not name numpy: $msg"
echo "$msg" | grep -q "built for" && ok "says which interpreter the build was for" || bad "no 'built for': $msg"
echo "$msg" | grep -qF "$py" && ok "names this interpreter ($py)" || bad "does not name $py: $msg"
# the interpreter it names imports the package and NumPy
built=$(echo "$msg" | sed -n 's/.*built for \([^ ,;()]*\).*/\1/p')
if [ -n "$built" ] && [ -x "$built" ]; then
    PYTHONPATH="$src/python" PYTHONDONTWRITEBYTECODE=1 "$built" -c 'import atmos, numpy' 2>"$T/err2" &&
        ok "the interpreter named ($built) imports atmos and numpy" || { bad "$built cannot import atmos"; cat "$T/err2" >&2; }
else
    bad "the message names no interpreter that exists: '$built'"
fi
exit $fail
