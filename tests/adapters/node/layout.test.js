'use strict';
// Every koffi struct of lib/capi_generated.js has the size and field offsets the C compiler gives the struct of
// embra.h (a small C program prints them).

const assert = require('node:assert/strict');
const { execFileSync } = require('node:child_process');
const fs = require('node:fs');
const path = require('node:path');
const test = require('node:test');

const { embra, sourceDir, tempDir } = require('./helpers');

const { capi } = embra;

/** Every (path, offset) of a struct's fields, nested structs and array elements included. */
function fields(type, prefix, base, out) {
  for (const [name, member] of Object.entries(type.members)) {
    const at = base + member.offset;
    const field = prefix ? `${prefix}.${name}` : name;
    out.push([field, at]);
    if (member.type.primitive === 'Record') fields(member.type, field, at, out);
    if (member.type.primitive === 'Array') {
      for (let i = 0; i < member.type.length; i++) out.push([`${field}[${i}]`, at + i * member.type.ref.size]);
    }
  }
  return out;
}

test('struct sizes and offsets equal the C compiler\'s', () => {
  const dir = tempDir('layout');
  const lines = ['#include <stddef.h>', '#include <stdio.h>', '#include "embra/embra.h"', 'int main(void) {'];
  const expected = [];
  for (const [cName, type] of Object.entries(capi.STRUCTS)) {
    lines.push(`  printf("${cName} %zu %zu\\n", sizeof(${cName}), _Alignof(${cName}));`);
    expected.push([cName, `${type.size} ${type.alignment}`]);
    for (const [field, offset] of fields(type, '', 0, [])) {
      lines.push(`  printf("${cName}.${field} %zu\\n", offsetof(${cName}, ${field}));`);
      expected.push([`${cName}.${field}`, String(offset)]);
    }
  }
  lines.push('  return 0;', '}');
  fs.writeFileSync(path.join(dir, 'layout.c'), lines.join('\n') + '\n');
  const generated = path.join(path.dirname(fs.realpathSync(process.env.EMBRA_LIBRARY)), 'generated');
  execFileSync(process.env.CC || 'cc', ['-std=c11', '-I', path.join(sourceDir, 'capi', 'include'), '-I', generated,
    '-o', path.join(dir, 'layout'), path.join(dir, 'layout.c')], { stdio: 'inherit' });
  const c = new Map(execFileSync(path.join(dir, 'layout'), { encoding: 'utf8' }).trim().split('\n')
    .map((line) => { const at = line.indexOf(' '); return [line.slice(0, at), line.slice(at + 1)]; }));
  assert.ok(expected.length > 200, `only ${expected.length} layout facts`);
  const wrong = expected.filter(([key, value]) => c.get(key) !== value)
    .map(([key, value]) => `${key}: koffi ${value}, C ${c.get(key)}`);
  assert.deepEqual(wrong, [], `layouts differ:\n  ${wrong.join('\n  ')}`);
});
