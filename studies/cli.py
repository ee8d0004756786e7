"""The ``rpdrill`` command line: one subcommand per module, each with ``add_arguments`` and ``run``.

Exit status: 0 success, 1 a run failed or a check did not pass, 2 bad input.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from studies.loading import InputError

COMMANDS = {
    "simulate": "studies.simulate_command",
    "crosscheck": "studies.crosscheck",
    "study": "studies.study_command",
}


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # argparse's own usage errors are bad input too
        self.print_usage(sys.stderr)
        print(f"rpdrill: error: {message}", file=sys.stderr)
        sys.exit(2)


def main(argv: list[str] | None = None) -> int:
    parser = _Parser(prog="rpdrill", description="Rotary-percussive drilling simulator on Exudyn")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=_Parser)
    modules = {}
    for name, module_name in COMMANDS.items():
        try:
            module = importlib.import_module(module_name)
        except ModuleNotFoundError as err:
            if err.name != module_name:
                raise
            continue
        modules[name] = module
        module.add_arguments(sub.add_parser(name, help=module.__doc__.strip().splitlines()[0]))
    args = parser.parse_args(argv)
    try:
        return int(modules[args.command].run(args))
    except InputError as err:
        print(str(err), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("rpdrill: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
