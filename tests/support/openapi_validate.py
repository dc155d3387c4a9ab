#!/usr/bin/python3
"""Validates real responses against the schemas of an OpenAPI 3.1 document (JSON Schema 2020-12,
Debian's python3-jsonschema).

usage: openapi_validate.py DOCUMENT MANIFEST
MANIFEST is a JSON list of {"method", "path", "status", "file"}: `path` is the document's path
template, `file` holds the response body. Prints one line per failure; exits 1 if any."""
import json
import sys

import jsonschema


def resolve(document, ref):
    node = document
    for part in ref.lstrip("#/").split("/"):
        node = node[part.replace("~1", "/").replace("~0", "~")]
    return node


def main():
    document = json.load(open(sys.argv[1]))
    manifest = json.load(open(sys.argv[2]))
    failures = 0
    for entry in manifest:
        where = "%s %s %s" % (entry["method"].upper(), entry["path"], entry["status"])
        try:
            op = document["paths"][entry["path"]][entry["method"].lower()]
            response = op["responses"][str(entry["status"])]
        except KeyError:
            print("%s: not described in the document" % where)
            failures += 1
            continue
        if "$ref" in response:
            response = resolve(document, response["$ref"])
        schema = response["content"]["application/json"]["schema"]
        # The schema's own $refs point into the document's components.
        root = dict(schema, components=document["components"])
        body = json.load(open(entry["file"]))
        validator = jsonschema.Draft202012Validator(root)
        errors = sorted(validator.iter_errors(body), key=lambda e: list(e.absolute_path))
        for e in errors:
            print("%s: %s at /%s" % (where, e.message, "/".join(str(p) for p in e.absolute_path)))
            failures += 1
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
