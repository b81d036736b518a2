#!/usr/bin/env python3
"""Lists the statements whose random draws the compiler may order as it likes.

    scripts/unsequenced_draws.py [--root DIR] [--fail] [--self-test] [FILE ...]

C++ leaves the order in which a call's arguments are evaluated unspecified: gcc evaluates them
last first, clang first to last. A call such as `Pose2(u(rng), u(rng), u(rng))` therefore draws
a different pose under each compiler, and so do the operands of one operator (an overloaded
`a * b` is a call: gcc evaluates b first). This scan flags, in every .h/.cc file git tracks (or
the files given):

  * a parenthesised call or constructor with random draws in two or more of its arguments;
  * two or more random draws in different operands of one operator, e.g.
    `RandomPose(rng) * RandomPose(rng)` or `0.1 * u(rng) + u(rng)`.

What is sequenced is accepted: a braced list `Pose2{u(rng), u(rng)}` (left to right), separate
declarators `double x = u(rng), y = u(rng);`, separate statements, `&&`, `||`, `?:`, `<<`, `>>`,
an assignment, and `a.f(x).g(y)` (the object before the arguments). The body of a lambda is not
evaluated where it is written, so its draws count only where the lambda is called.

A random draw is, syntactically:
  * a call with an engine among its arguments: `u(rng)`, `Sample(*rng, 3)`, `Shuffle(&engine_)`;
  * a member call on an engine: `rng.Uniform()`, `rng_->Gaussian()`, or calling it: `engine_()`;
  * a call of a lambda of the same file whose body draws (`auto noise = [&] { return n(rng); }`).
An engine is a name such as rng, rng_, engine, engine_, foo_rng, or a variable the file declares
with an engine type (std::mt19937, RandomEngine, RandomStream, Rng, ...). Draws hidden in an
object that keeps its own engine are not seen.

Prints file:line for each finding; with --fail the exit status is 1 when there is any.
--self-test checks the scan itself on small snippets (exit 1 on a mistake).
"""

import argparse
import os
import re
import subprocess
import sys

ENGINE_NAME = re.compile(r"^(?:\w+_)?(?:rng|engine)_?$", re.I)
ENGINE_TYPES = (r"std::mt19937(?:_64)?|std::minstd_rand0?|std::default_random_engine|"
                r"std::ranlux\w*|std::knuth_b|RandomEngine|RandomStream|Rng")
ENGINE_DECL = re.compile(r"\b(?:" + ENGINE_TYPES + r")\s*[&*]?\s+(\w+)\s*[({=;,)]")
KEYWORDS = {"if", "for", "while", "switch", "return", "catch", "sizeof", "alignof", "decltype",
            "noexcept", "co_return", "co_yield", "throw", "case", "static_assert", "new",
            "delete", "operator", "requires", "alignas", "typeid"}
# Tokens after which the left and right parts of an expression are sequenced (or are not one
# expression at all).
SEQUENCING = {";", "&&", "||", "?", ":", "<<", ">>", "=", "+=", "-=", "*=", "/=", "%=", "&=",
              "|=", "^=", "<<=", ">>=", "return", "co_return", "throw"}
PUNCT = re.compile(r"<<=|>>=|->\*|->|::|<<|>>|&&|\|\||<=|>=|==|!=|\+\+|--|[-+*/%&|^!=<>]=|"
                   r"[][(){};,.?:~!+\-*/%&|^<>=#]")
TOKEN = re.compile(r"\s*(?:([A-Za-z_]\w*)|(\d[\w.']*(?:[eEpP][-+]\d+)?\w*)|(" + PUNCT.pattern +
                   r")|(\S))")


BLANKED = re.compile(r"//[^\n]*|/\*.*?\*/|\bR\"([^(\s]*)\(.*?\)\1\"|\"(?:\\.|[^\"\\\n])*\"|"
                     r"(?<![\w'])'(?:\\.|[^'\\\n])*'|^[ \t]*#(?:\\\n|[^\n])*", re.S | re.M)


def StripComments(text):
    """The source with comments, string/char literals and preprocessor lines blanked out (a
    literal becomes the token 0); newlines are kept so that offsets keep their line numbers."""

    def Blank(m):
        kept = re.sub(r"[^\n]", " ", m.group(0))
        return "0" + kept[1:] if m.group(0)[0] in "\"'R" else kept

    return BLANKED.sub(Blank, text)


def Tokens(text):
    """(token, line) pairs of blanked source."""
    line, pos, out = 1, 0, []
    for m in TOKEN.finditer(text):
        line += text.count("\n", pos, m.start(m.lastindex))
        pos = m.start(m.lastindex)
        out.append((m.group(m.lastindex), line))
    return out


class Group:
    """A bracketed part of the source: its opening token, line and children (tokens or groups)."""

    def __init__(self, open_token, line):
        self.open, self.line, self.children = open_token, line, []
        self.kind = None  # "call", "paren", "brace", "lambda", "square"; set by Classify
        self.draw = False  # this group's parentheses are a random draw


def Tree(tokens):
    root = Group("", 0)
    stack = [root]
    for tok, line in tokens:
        if tok in "([{" and len(tok) == 1:
            g = Group(tok, line)
            stack[-1].children.append(g)
            stack.append(g)
        elif tok in ")]}" and len(tok) == 1:
            if len(stack) > 1:
                stack.pop()
        else:
            stack[-1].children.append((tok, line))
    return root


def IsName(item):
    return isinstance(item, tuple) and re.match(r"^[A-Za-z_]\w*$", item[0]) is not None


def Text(item):
    return item[0] if isinstance(item, tuple) else item.open


def SplitTopLevel(children, separators):
    parts, current = [], []
    for c in children:
        if isinstance(c, tuple) and c[0] in separators:
            parts.append(current)
            current = []
        else:
            current.append(c)
    parts.append(current)
    return parts


CONTROL = {"if", "while", "for", "switch", "catch"}


def SplitStatements(children):
    """Parts of a block, a braced list or a grouping parenthesis that are sequenced one after
    another: split at sequencing tokens and commas, after a block (braces holding a `;`) and
    after the condition of if/while/for/switch."""
    parts, current = [], []
    for k, c in enumerate(children):
        if isinstance(c, tuple):
            if c[0] in SEQUENCING or c[0] in (",", "else", "do", "try"):
                parts.append(current)
                current = []
            else:
                current.append(c)
            continue
        current.append(c)
        block = c.open == "{" and any(Text(t) == ";" for t in c.children)
        condition = c.open == "(" and k > 0 and Text(children[k - 1]) in CONTROL
        if block or condition:
            parts.append(current)
            current = []
    parts.append(current)
    return parts


class Scan:
    def __init__(self, path, text):
        self.path = path
        self.engines = set(ENGINE_DECL.findall(text))
        self.root = Tree(Tokens(StripComments(text)))
        self.drawing_lambdas = set()
        self.findings = []

    def IsEngine(self, name):
        return name in self.engines or ENGINE_NAME.match(name) is not None

    def Classify(self, group):
        """Sets kind and draw for every group below `group` (children before parents)."""
        kids = group.children
        for i, c in enumerate(kids):
            if not isinstance(c, Group):
                continue
            prev = kids[i - 1] if i > 0 else None
            prev_text = Text(prev) if prev is not None else ""
            if c.open == "(":
                callable_prev = (IsName(prev) and prev_text not in KEYWORDS) or \
                    (isinstance(prev, Group) and prev.open in "([") or prev_text == ">"
                c.kind = "call" if callable_prev else "paren"
            elif c.open == "{":
                c.kind = "lambda" if (isinstance(prev, Group) and prev.open in "([") or \
                    prev_text in ("mutable", "const", "noexcept") or \
                    (i >= 2 and Text(kids[i - 2]) == "->") else "brace"
            else:
                c.kind = "square"
            self.Classify(c)
            if c.kind == "call":
                c.draw = self.IsDrawCall(kids, i)
        self.FindLambdas(kids)

    def IsDrawCall(self, kids, i):
        call = kids[i]
        for arg in SplitTopLevel(call.children, {","}):
            names = [Text(t) for t in arg]
            if len(names) in (1, 2) and IsName(arg[-1]) and self.IsEngine(names[-1]) and \
                    (len(names) == 1 or names[0] in ("*", "&")):
                return True
        prev = kids[i - 1] if i > 0 else None
        if IsName(prev):
            name = Text(prev)
            if name in self.drawing_lambdas:
                return True
            if self.IsEngine(name) and not call.children and \
                    (i < 2 or Text(kids[i - 2]) not in (".", "->", "::")):
                return True  # engine_()
            if i >= 3 and Text(kids[i - 2]) in (".", "->") and IsName(kids[i - 3]) and \
                    self.IsEngine(Text(kids[i - 3])):
                return True  # rng.Uniform(), rng_->Gaussian()
        return False

    def FindLambdas(self, kids):
        """`auto name = [..](..) { body }` whose body draws: calling `name` is a draw."""
        for i in range(len(kids) - 3):
            if Text(kids[i]) == "auto" and IsName(kids[i + 1]) and Text(kids[i + 2]) == "=" and \
                    isinstance(kids[i + 3], Group) and kids[i + 3].open == "[":
                for c in kids[i + 4:i + 8]:
                    if isinstance(c, Group) and c.kind == "lambda":
                        if self.Draws(c, into_lambdas=True):
                            self.drawing_lambdas.add(Text(kids[i + 1]))
                        break

    def Draws(self, item, into_lambdas=False):
        """True when evaluating `item` draws (a lambda's body is not evaluated where written)."""
        if not isinstance(item, Group):
            return False
        if item.kind == "lambda" and not into_lambdas:
            return False
        return item.draw or any(self.Draws(c, into_lambdas) for c in item.children)

    def CheckOperands(self, items):
        """Flags draws in different operands of one expression: `items` holds no sequencing
        token. Postfix chains (`a(x).b(y)`) are sequenced left to right."""
        drawing = [k for k, c in enumerate(items) if self.Draws(c)]
        for a, b in zip(drawing, drawing[1:]):
            between = items[a + 1:b]
            chain = all(Text(t) in (".", "->", "::") or IsName(t) or
                        (isinstance(t, Group) and t.kind in ("call", "square")) for t in between)
            if not chain:
                line = items[a].line if isinstance(items[a], Group) else items[a][1]
                self.findings.append((line, "random draws in two operands of one expression"))
                return

    def Check(self, group):
        kids = group.children
        if group.kind == "call":
            args = SplitTopLevel(kids, {","})
            if sum(1 for arg in args if any(self.Draws(c) for c in arg)) >= 2:
                self.findings.append((group.line, "random draws in two arguments of one call"))
            parts = [p for arg in args for p in SplitTopLevel(arg, SEQUENCING)]
        else:
            # Braces, statements and grouping parentheses: commas are sequenced (list elements,
            # declarators, the comma operator), and so are statements.
            parts = SplitStatements(kids)
        for part in parts:
            self.CheckOperands(part)
        for c in kids:
            if isinstance(c, Group):
                self.Check(c)

    def Run(self):
        self.Classify(self.root)
        self.Classify(self.root)  # again: lambdas found in the first pass now count as draws
        self.Check(self.root)
        return sorted(set(self.findings))


ANY_ENGINE = re.compile(r"\b(?:\w+_)?(?:rng|engine)_?\b|\b(?:" + ENGINE_TYPES + r")\b", re.I)


def Findings(path, text):
    lower = text.lower()
    if "rng" not in lower and "engine" not in lower and not ANY_ENGINE.search(text):
        return []  # most files: no engine, nothing draws (a fast path, same answer)
    return Scan(path, text).Run()


SELF_TEST = [
    # (snippet, number of findings)
    ("Pose2 p(u(rng), u(rng), u(rng));", 1),
    ("const Pose2 a(u(rng), u(rng), u(rng)),\n    b(u(rng), u(rng), u(rng));", 2),
    ("x = Eigen::Vector2d(Uniform01(rng), Uniform01(rng));", 1),
    ("f(0.1 * rng.Uniform(), rng_->Gaussian());", 1),
    ("v.emplace_back(n(*rng), 2.0 * n(*rng));", 1),
    ("return Pose2(xy(rng), xy(rng), angle(rng));", 1),
    ("const Pose2 c = RandomPose(rng) * RandomPose(rng);", 1),
    ("double s = u(rng) + 0.5 * u(rng);", 1),
    ("Pose2 p(f(u(rng)), 2.0);", 0),
    ("auto noise = [&] { return n(rng); };\nPose2 p(noise(), noise(), 0.0);", 1),
    ("std::mt19937 more(1);\nPose2 p(u(more), u(more), 0.0);", 1),
    ("Pose2 p{u(rng), u(rng), u(rng)};", 0),
    ("const Eigen::Vector2d v{u(rng), u(rng)};", 0),
    ("double x = u(rng), y = u(rng);", 0),
    ("const double y = u(rng);\nconst double x = u(rng);\nPose2 p(x, y, 0.0);", 0),
    ("Pose2 p(u(rng), 1.0, 2.0);", 0),
    ("auto f = [&](int k) { return Pose2(k, 0, 0); };\nf(u(rng));", 0),
    ("std::generate(v.begin(), v.end(), [&] { return u(rng); });", 0),
    ("ok = u(rng) < 0.5 && u(rng) < 0.5;", 0),
    ("x = flip(rng) ? u(rng) : 0.0;", 0),
    ("std::cout << u(rng) << u(rng);", 0),
    ("std::mt19937 rng(42); Rng r(7); rng.seed(3);", 0),
    ("// Pose2(u(rng), u(rng))\nconst char* s = \"f(u(rng), u(rng))\";", 0),
    ("x = Make(rng).Scale(u(rng));", 0),
    ("if (rng.Chance(0.5)) {\n  a = 1;\n}\nf(u(rng));", 0),
    ("if (u(rng) < 0.5) f(u(rng));\nfor (int i = u(rng); i < 3; ++i) g(u(rng));", 0),
    ("void F(Rng& rng) {\n  a = rng.Uniform();\n}\nvoid G(Rng& rng) { b = rng.Uniform(); }", 0),
]


def SelfTest():
    failures = 0
    for snippet, expected in SELF_TEST:
        got = Findings("<self-test>", snippet)
        if len(got) != expected:
            failures += 1
            print(f"self-test: expected {expected} finding(s), got {len(got)} {got} in:\n"
                  f"    {snippet}")
    print(f"unsequenced_draws self-test: {len(SELF_TEST) - failures}/{len(SELF_TEST)} snippets "
          "right")
    return 1 if failures else 0


def TrackedFiles(root):
    try:
        out = subprocess.run(["git", "ls-files", "*.h", "*.cc"], cwd=root, check=True,
                             capture_output=True, text=True).stdout
        return out.split()
    except (OSError, subprocess.CalledProcessError):
        print("unsequenced_draws: not a git checkout (the scan reads git's list of files)",
              file=sys.stderr)
        sys.exit(77)  # CTest's skip code


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="*")
    parser.add_argument("--root", default=os.path.join(os.path.dirname(__file__), ".."))
    parser.add_argument("--fail", action="store_true", help="exit 1 when anything is found")
    parser.add_argument("--self-test", action="store_true")
    args = parser.parse_args()
    if args.self_test:
        return SelfTest()

    count = 0
    for path in args.files or TrackedFiles(args.root):
        with open(os.path.join(args.root, path), encoding="utf-8", errors="replace") as f:
            text = f.read()
        for line, what in Findings(path, text):
            print(f"{path}:{line}: {what}")
            count += 1
    print(f"unsequenced_draws: {count} statement(s) whose random draws are unsequenced")
    return 1 if args.fail and count else 0


if __name__ == "__main__":
    sys.exit(main())
