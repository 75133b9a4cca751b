#!/bin/sh
# Reproduces the reference paper's studies: see paper/reproduce.py --help.
# Debian's python3 first: the figures need its python3-matplotlib.
py=python3
[ -x /usr/bin/python3 ] && py=/usr/bin/python3
exec "$py" "$(dirname "$0")/reproduce.py" "$@"
