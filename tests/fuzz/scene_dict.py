#!/usr/bin/env python3
"""Writes fuzz_scene's libFuzzer dictionary from the scene schema (schemas/scene.schema.json), so
the dictionary never drifts from the format: every property name as a quoted JSON key, every
string const and enum value as a quoted JSON string, every numeric bound (minimum, maximum, ...)
and its neighbours as a number, and the JSON punctuation.

    scene_dict.py SCHEMA OUT
"""
import json
import sys

BOUNDS = ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "minItems", "maxItems")


def walk(node, strings, numbers):
    if isinstance(node, dict):
        for key, value in node.items():
            if key == "properties" and isinstance(value, dict):
                strings.update(value.keys())
            elif key == "const" and isinstance(value, str):
                strings.add(value)
            elif key == "enum" and isinstance(value, list):
                strings.update(v for v in value if isinstance(v, str))
            elif key in BOUNDS and isinstance(value, (int, float)) and not isinstance(value, bool):
                numbers.add(value)
            walk(value, strings, numbers)
    elif isinstance(node, list):
        for value in node:
            walk(value, strings, numbers)


def quoted(text):
    """One libFuzzer dictionary entry: the text between double quotes, escaped."""
    out = []
    for byte in text.encode("utf-8"):
        c = chr(byte)
        if c in '"\\':
            out.append("\\" + c)
        elif 0x20 <= byte < 0x7F:
            out.append(c)
        else:
            out.append("\\x%02X" % byte)
    return '"' + "".join(out) + '"'


def number_tokens(value):
    """A bound, and the numbers just inside and outside it as JSON writes them."""
    if isinstance(value, int):
        return {str(value), str(value - 1), str(value + 1)}
    text = repr(value)
    return {text, "-" + text}


def main():
    schema_path, out_path = sys.argv[1], sys.argv[2]
    with open(schema_path, encoding="utf-8") as f:
        schema = json.load(f)
    strings, numbers = set(), set()
    walk(schema, strings, numbers)
    entries = set()
    for s in strings:
        entries.add(json.dumps(s))  # "name" as a JSON string
        entries.add(json.dumps(s) + ":")  # "name": as a key
    for n in numbers:
        entries.update(number_tokens(n))
    entries.update(["{", "}", "[", "]", ",", ":", "true", "false", "null", "1e300", "-1e300", "1e-300", "1e301",
                    "1.7976931348623157e308", "5e-324", "NaN", "Infinity", "-0", "0.0", "[0, 0, 0]",
                    "[1, 0, 0, 0]"])
    with open(out_path, "w", encoding="utf-8") as f:
        f.write("# Generated from %s by tests/fuzz/scene_dict.py: do not edit.\n" % schema_path.split("/")[-1])
        for i, entry in enumerate(sorted(entries)):
            f.write("kw%d=%s\n" % (i, quoted(entry)))


if __name__ == "__main__":
    main()
