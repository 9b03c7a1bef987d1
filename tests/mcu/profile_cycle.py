#!/usr/bin/python3
"""Where a cycle of jg_cycle_bench.elf spends its instructions (a development tool, not a test).

Runs the ELF under qemu -singlestep with execution tracing (as `jointguard bench` does),
keeps the PCs executed between jg_bench_begin/jg_bench_end of one section and prints the
instructions per cycle by function (nm), by innermost inlined source line and by inline
chain (addr2line -i; build with -g, which does not change the code), and by mnemonic.
Sections (tests/mcu/cycle_bench.cpp): 0 estimator float, 1 estimator Q16.16 (one marker
pair around 20 cycles: divide by 20), 2 drive float, 3 drive Q16.16.

  cmake -S . -B build/m4g -DCMAKE_TOOLCHAIN_FILE=$PWD/toolchain/arm-none-eabi.cmake \\
        -DJG_MCU_CPU=cortex-m4 -DCMAKE_BUILD_TYPE=Release "-DCMAKE_CXX_FLAGS_RELEASE=-O3 -DNDEBUG -g"
  cmake --build build/m4g --target jg_cycle_bench
  /usr/bin/python3 tests/mcu/profile_cycle.py build/m4g/toolchain/mcu/jg_cycle_bench.elf mps2-an386 2 [FUNCTION]

With FUNCTION (a substring of a demangled name) the function's disassembly is printed with
the executions per cycle of every instruction.
"""
import bisect
import collections
import os
import subprocess
import sys
import tempfile


def main():
    elf = sys.argv[1]
    machine = sys.argv[2] if len(sys.argv) > 2 else 'mps2-an386'
    want = int(sys.argv[3]) if len(sys.argv) > 3 else 2
    syms = []
    for line in subprocess.run(['arm-none-eabi-nm', '-S', '-C', '--defined-only', elf],
                               capture_output=True, text=True, check=True).stdout.splitlines():
        parts = line.split(None, 3)
        if len(parts) == 4 and parts[2] in 'tTwW':
            syms.append((int(parts[0], 16) & ~1, int(parts[1], 16), parts[3]))
    raw = {}
    for line in subprocess.run(['arm-none-eabi-nm', elf], capture_output=True, text=True, check=True).stdout.splitlines():
        p = line.split()
        if len(p) == 3:
            raw[p[2]] = int(p[0], 16) & ~1
    syms.sort()
    starts = [s[0] for s in syms]
    with tempfile.TemporaryDirectory() as tmp:
        log = os.path.join(tmp, 'trace.log')
        subprocess.run(f'qemu-system-arm -M {machine} -nographic -monitor none -serial none '
                       f'-semihosting-config enable=on,target=native -singlestep -d nochain,exec -D {log} -kernel {elf}',
                       shell=True, capture_output=True, check=False)
        sec, inside, ncyc = -1, False, 0
        hist = collections.Counter()
        with open(log, encoding='ascii', errors='replace') as f:
            for line in f:
                if not line.startswith('Trace'):
                    continue
                o = line.find('[')
                s = line.find('/', o)
                pc = int(line[s + 1:line.find('/', s + 1)], 16)
                if pc == raw['jg_bench_section']:
                    sec += 1
                    continue
                if sec != want:
                    continue
                if pc == raw['jg_bench_begin']:
                    inside = True
                    ncyc += 1
                elif pc == raw['jg_bench_end']:
                    inside = False
                elif inside:
                    hist[pc] += 1
    if ncyc == 0:
        sys.exit('no cycles found in section %d' % want)
    print('cycles', ncyc, 'instructions per cycle', sum(hist.values()) / ncyc)
    fn = collections.Counter()
    for pc, n in hist.items():
        i = bisect.bisect_right(starts, pc) - 1
        fn[syms[i][2] if i >= 0 and pc < syms[i][0] + max(syms[i][1], 1) else hex(pc)] += n
    print('--- by function')
    for name, n in fn.most_common(25):
        print(f'{n / ncyc:8.1f}  {name[:150]}')
    pcs = sorted(hist)
    out = subprocess.run(['arm-none-eabi-addr2line', '-e', elf, '-i', '-f', '-C', '-a'] + [hex(p) for p in pcs],
                         capture_output=True, text=True, check=True).stdout.splitlines()
    info, cur, i = {}, None, 0
    while i < len(out):
        if out[i].startswith('0x'):
            cur = int(out[i], 16)
            info[cur] = []
            i += 1
            continue
        info[cur].append((out[i], out[i + 1]))
        i += 2
    byline, bychain = collections.Counter(), collections.Counter()
    for pc, n in hist.items():
        chain = info.get(pc, [])
        if chain:
            f, loc = chain[0]
            byline[os.path.basename(loc.split(' ')[0]) + ' ' + f[:60]] += n
            bychain[' < '.join(os.path.basename(c[1].split(' ')[0]) for c in chain[:3])] += n
    print('--- by innermost source line')
    for k, n in byline.most_common(60):
        print(f'{n / ncyc:8.1f}  {k}')
    print('--- by inline chain (3 levels)')
    for k, n in bychain.most_common(40):
        print(f'{n / ncyc:8.1f}  {k}')
    dis = subprocess.run(['arm-none-eabi-objdump', '-d', '--no-show-raw-insn', '-C', elf],
                         capture_output=True, text=True, check=True).stdout.splitlines()
    mnemonic = {}
    for line in dis:
        p = line.split('\t')
        if len(p) >= 2 and p[0].strip().endswith(':'):
            try:
                mnemonic[int(p[0].strip()[:-1], 16)] = p[1].split()[0] if p[1].split() else '?'
            except ValueError:
                pass
    mh = collections.Counter()
    for pc, n in hist.items():
        mh[mnemonic.get(pc, '?')] += n
    print('--- by mnemonic')
    print(' '.join(f'{k}:{v / ncyc:.0f}' for k, v in mh.most_common(40)))
    if len(sys.argv) > 4:
        current = False
        for line in dis:
            if line.endswith('>:'):
                current = sys.argv[4] in line
            if current:
                try:
                    a = int(line.split(':', 1)[0].strip(), 16)
                except ValueError:
                    print(line)
                    continue
                print(f'{hist.get(a, 0) / ncyc:6.1f} {line}')


if __name__ == '__main__':
    main()
