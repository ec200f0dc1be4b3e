# The eight longest functions under the given folders (STYLE: ~150 lines at most). Usage:
#   python3 tools/function_lengths.py src parser
# Function lengths at any indentation: a header line holds '(' and ends a signature with '{' (or the next
# line is '{'); the body ends where the braces balance (strings, chars and // comments skipped).
import sys, pathlib, re
KEYWORDS = ('if', 'for', 'while', 'switch', 'catch', 'else', 'do', 'return', 'namespace', 'struct', 'class', 'enum')
def strip(l):
    l = re.sub(r'"(\\.|[^"\\])*"', '""', l)
    l = re.sub(r"'(\\.|[^'\\])*'", "''", l)
    return l.split('//')[0]
res = []
for root in sys.argv[1:]:
    for p in pathlib.Path(root).rglob('*'):
        if p.suffix not in ('.cpp', '.h'): continue
        lines = [strip(l) for l in p.read_text(errors='replace').split('\n')]
        i = 0
        while i < len(lines):
            l = lines[i].strip()
            k = i
            while l.endswith(',') and '(' in l and k + 1 < len(lines) and k - i < 4:  # a signature over lines
                k += 1
                l += ' ' + lines[k].strip()
            head = re.match(r'[\w:~<>]+', l)
            sig = i
            is_fn = ('(' in l and l.endswith('{') and head and head.group(0) not in KEYWORDS and '=' not in l.split('(')[0]
                     and not l.startswith(('[', '}')) and ')' in l and '[' not in l.split('(')[0])
            if is_fn:
                depth, j = 0, k
                while j < len(lines):
                    depth += lines[j].count('{') - lines[j].count('}')
                    if depth <= 0: break
                    j += 1
                res.append((j - i + 1, f'{p}:{i+1}', l[:70]))
            i += 1
res.sort(reverse=True)
for r in res[:8]:
    print(*r)
