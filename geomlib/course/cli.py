"""``geomlib-course``: the lecturer's command for a class (see :mod:`geomlib.course`)."""

import argparse
import sys


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="geomlib-course", description="Grade a class with nbgrader in parallel and read its mistakes."
    )
    commands = parser.add_subparsers(dest="command", required=True)
    grade = commands.add_parser(
        "autograde", help="nbgrader autograde of every submitted student, several at once, with progress"
    )
    grade.add_argument("course_dir", help="the course folder (where nbgrader_config.py is)")
    grade.add_argument("assignment")
    grade.add_argument("--workers", type=int, default=1, help="students graded at once (default 1)")
    grade.add_argument("--student", action="append", help="grade only this student (repeatable)")
    grade.add_argument("--force", action="store_true", help="regrade students already graded")
    report = commands.add_parser("report", help="the class report: pass rates, mistakes, waiting answers, copies")
    report.add_argument("course_dir")
    report.add_argument("assignment")
    args = parser.parse_args(argv)

    if args.command == "autograde":
        from .autograde import autograde_class

        graded = autograde_class(
            args.course_dir, args.assignment, workers=args.workers, students=args.student, force=args.force
        )
        failed = [g for g in graded if not g.ok]
        for g in failed:
            print(f"\n--- nbgrader autograde --student {g.student} failed:\n{g.log[-3000:]}", file=sys.stderr)
        if graded:
            mean = sum(g.seconds for g in graded) / len(graded)
            print(f"{len(graded) - len(failed)} of {len(graded)} students graded, {mean:.1f} s per student")
        return 1 if failed else 0
    from .report import write_report

    paths = write_report(args.course_dir, args.assignment)
    for path in paths:
        print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
