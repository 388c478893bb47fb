"""Reads a yarnhom trace with the official MCAP Python library (PyPI `mcap`) and checks every
message against the JSON Schema stored with its channel: msgpack payloads whose keys are the
schema's properties, every required property present. Prints what it saw as JSON."""

import json
import sys

import msgpack
from mcap.reader import make_reader

JSON_TYPES = {
    "object": dict,
    "array": list,
    "string": str,
    "boolean": bool,
    "integer": int,
    "number": (int, float),
    "null": type(None),
}


def check_type(value, schema, where):
    """The top-level JSON type of `value` is one the schema allows."""
    allowed = schema.get("type")
    if allowed is None:
        return
    allowed = allowed if isinstance(allowed, list) else [allowed]
    if not any(isinstance(value, JSON_TYPES[t]) and not (t in ("integer", "number") and isinstance(value, bool)) for t in allowed):
        raise SystemExit(f"{where}: {type(value).__name__} is not {allowed}")


def main(path):
    messages, schemas, metadata = {}, {}, 0
    with open(path, "rb") as f:
        reader = make_reader(f)
        for schema, channel, message in reader.iter_messages():
            assert channel.message_encoding == "msgpack", channel.message_encoding
            assert schema.encoding == "jsonschema", schema.encoding
            spec = json.loads(schema.data)
            payload = msgpack.unpackb(message.data, raw=False)
            props = spec.get("properties", {})
            extra = set(payload) - set(props)
            missing = set(spec.get("required", [])) - set(payload)
            if extra or missing:
                raise SystemExit(f"{channel.topic}: extra {extra}, missing {missing}")
            for key, value in payload.items():
                check_type(value, props[key], f"{channel.topic}.{key}")
            messages[channel.topic] = messages.get(channel.topic, 0) + 1
            schemas[channel.topic] = schema.name
        metadata = sum(1 for _ in reader.iter_metadata())
    print(json.dumps({"messages": messages, "schemas": schemas, "metadata": metadata}))


if __name__ == "__main__":
    main(sys.argv[1])
