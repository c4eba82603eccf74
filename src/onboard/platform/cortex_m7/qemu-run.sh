#!/bin/sh
# Runs a Cortex-M7 image on QEMU's mps2-an500 with semihosting: qemu-run.sh <image.elf> [arguments...]
#
# The program's arguments travel in the semihosting configuration (arg=...; the startup code reads
# them with SYS_GET_CMDLINE), its files are opened by QEMU relative to the current directory, and QEMU's
# exit status is the program's (the startup code exits with SYS_EXIT_EXTENDED, which QEMU 7.2 honours
# on 32-bit Arm: checked with statuses 0, 1, 90, 91, 92, 94). -icount shift=0: one
# virtual nanosecond per instruction, so that ffsr_cycles() counts instructions; it also makes the run
# deterministic. Arguments cannot contain spaces or commas (QEMU's option syntax).
# Set FFSR_QEMU_TIMEOUT (seconds, default 600) to bound a run that hangs.
set -eu
if [ $# -lt 1 ]; then
  echo "usage: $0 <image.elf> [arguments...]" >&2
  exit 2
fi
image=$1
shift
config="enable=on,target=native,arg=$(basename "$image")"
for argument in "$@"; do
  case $argument in
    *[\ ,]*) echo "qemu-run.sh: argument with a space or comma: $argument" >&2; exit 2 ;;
  esac
  config="$config,arg=$argument"
done
exec timeout "${FFSR_QEMU_TIMEOUT:-600}" qemu-system-arm -M mps2-an500 -nographic -monitor none \
  -serial none -semihosting-config "$config" -icount shift=0 -kernel "$image"
