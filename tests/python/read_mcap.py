#!/usr/bin/env python3
"""Independent reader of clutchpack recordings, built on the official MCAP Python packages
(`mcap`, `mcap-protobuf-support`): decodes EVERY message of every channel of an MCAP file
with the protobuf schemas embedded in the file, and prints the schema names and the message
counts per topic.

    py=$(bash tests/python/setup.sh)
    "$py" tests/python/read_mcap.py FILE.mcap [--json] [--allow-truncated]
                                    [--expect-schema TOPIC=SCHEMA ...]

Two passes:
1. a streaming pass over every record from the start (chunk and data-section CRCs checked),
   decoding each message in file order: this is what recovers a killed run's messages;
2. for a complete file, an indexed pass through the summary section (chunk and message
   indexes), decoding each message again; both passes and the summary's statistics must
   agree on the count of every channel.

Exit status: 0 when everything decoded (with --allow-truncated, also when the file merely
ends early, after the messages before that point decoded); 1 on any failure (undecodable
message, CRC mismatch, corrupt record, disagreeing counts, a wrong schema name), with a
one-line reason on stderr; 2 on bad usage.

The schemas of /tf and /scene, when present, must be exactly `foxglove.FrameTransforms` and
`foxglove.SceneUpdate`; --expect-schema adds more such checks.

--json prints one JSON object on stdout: file, complete, summary_section, messages, error,
truncated, topics {topic: {schema, schema_encoding, message_encoding, count, first_log_time,
last_log_time, first, last}}, metadata (names), attachments (names), summary (the decoded
/summary message, if any). `first` and `last` are the decoded first and last messages of the
topic as dicts (clutchpack.* schemas only).
"""

import argparse
import json
import os
import sys

try:
    from google.protobuf.json_format import MessageToDict
    from mcap import exceptions as mcap_exceptions
    from mcap.reader import make_reader
    from mcap.records import (
        Attachment,
        Channel,
        DataEnd,
        Footer,
        Message,
        Metadata,
        Schema,
        Statistics,
    )
    from mcap.stream_reader import StreamReader
    from mcap_protobuf.decoder import DecoderFactory
    from mcap_ros2.decoder import DecoderFactory as Ros2DecoderFactory
except ImportError as e:  # pragma: no cover
    print(f"read_mcap.py: missing package ({e}); run tests/python/setup.sh", file=sys.stderr)
    sys.exit(1)

REQUIRED_SCHEMAS = {
    "/tf": "foxglove.FrameTransforms",
    "/scene": "foxglove.SceneUpdate",
}


class Failure(Exception):
    pass


MAGIC = b"\x89MCAP0\r\n"


def to_dict(msg):
    """The message as a dict with every field, zeros included (uint64 values are strings)."""
    try:
        return MessageToDict(
            msg, preserving_proto_field_name=True, always_print_fields_with_no_presence=True
        )
    except TypeError:  # protobuf < 5.26
        return MessageToDict(
            msg, preserving_proto_field_name=True, including_default_value_fields=True
        )


def check_magic(path):
    with open(path, "rb") as f:
        head = f.read(8)
    if not head:
        raise Failure("the file is empty")
    if head != MAGIC[: len(head)]:
        raise Failure(f"not an MCAP file (it starts with {head!r})")


def chunk_runs_past_end(path, at):
    """Whether a chunk record starts at byte `at` whose stated length runs past the end of the
    file: the chunk a killed run was writing (the recorder writes a chunk in place, its length
    a placeholder until the chunk ends), which the reader refuses by its length before it
    reaches the end of the file."""
    if at < 0:
        return False
    with open(path, "rb") as g:
        g.seek(at)
        head = g.read(9)
    if len(head) < 9 or head[0] != 0x06:  # the Chunk opcode
        return False
    return at + 9 + int.from_bytes(head[1:9], "little") > os.path.getsize(path)


def stream_pass(path, report):
    """Reads every record from the start, decoding every message. Returns (complete, error)."""
    factories = [DecoderFactory(), Ros2DecoderFactory()]
    schemas = {}
    channels = {}
    decoders = {}
    topics = report["topics"]
    data_end = footer = False
    stats = None
    with open(path, "rb") as f:
        reader = StreamReader(f, validate_crcs=True)
        try:
            for record in reader.records:
                if isinstance(record, Schema):
                    schemas[record.id] = record
                elif isinstance(record, Channel):
                    if record.schema_id != 0 and record.schema_id not in schemas:
                        raise Failure(f"channel {record.topic} refers to unknown schema {record.schema_id}")
                    if record.id not in channels:
                        channels[record.id] = record
                        schema = schemas.get(record.schema_id)
                        topics.setdefault(
                            record.topic,
                            {
                                "schema": schema.name if schema else "",
                                "schema_encoding": schema.encoding if schema else "",
                                "message_encoding": record.message_encoding,
                                "count": 0,
                                "first_log_time": None,
                                "last_log_time": None,
                                "first": None,
                                "last": None,
                            },
                        )
                elif isinstance(record, Message):
                    if data_end:
                        continue
                    channel = channels.get(record.channel_id)
                    if channel is None:
                        raise Failure(f"message on unknown channel {record.channel_id}")
                    schema = schemas.get(channel.schema_id)
                    decoder = decoders.get(channel.id)
                    if decoder is None:
                        decoder = next(
                            (
                                d
                                for d in (
                                    f.decoder_for(channel.message_encoding, schema)
                                    for f in factories
                                )
                                if d is not None
                            ),
                            None,
                        )
                        if decoder is None:
                            raise Failure(
                                f"no decoder for {channel.topic} (message encoding "
                                f"{channel.message_encoding!r}, schema "
                                f"{schema.encoding if schema else None!r})"
                            )
                        decoders[channel.id] = decoder
                    try:
                        decoded = decoder(record.data)
                    except Exception as e:  # any decode error is a failure
                        raise Failure(
                            f"message {topics[channel.topic]['count']} on {channel.topic} does not "
                            f"decode as {schema.name if schema else '?'}: {e}"
                        )
                    t = topics[channel.topic]
                    t["count"] += 1
                    report["messages"] += 1
                    if t["first_log_time"] is None:
                        t["first_log_time"] = record.log_time
                    t["last_log_time"] = record.log_time
                    if schema is not None and schema.name.startswith("clutchpack."):
                        d = to_dict(decoded)
                        if t["first"] is None:
                            t["first"] = d
                        t["last"] = d
                        if schema.name == "clutchpack.RunSummary":
                            report["summary"] = d
                elif isinstance(record, Metadata):
                    if not data_end:
                        report["metadata"].append(record.name)
                elif isinstance(record, Attachment):
                    if not data_end:
                        report["attachments"].append(record.name)
                elif isinstance(record, DataEnd):
                    data_end = True
                elif isinstance(record, Statistics):
                    stats = record
                elif isinstance(record, Footer):
                    footer = True
        except Failure:
            raise
        except Exception as e:
            # a reader that stopped at the end of the file met a truncation; anywhere else,
            # bad bytes
            at_end = (
                f.tell() >= os.path.getsize(path)
                or isinstance(e, mcap_exceptions.EndOfFile)
                or chunk_runs_past_end(path, f.tell() - 9)
            )
            what = f"{type(e).__name__}: {e}"
            if at_end:
                return False, stats, f"the file ends early (truncated) after {report['messages']} messages ({what})", True
            return False, stats, f"bad bytes near byte {f.tell()} after {report['messages']} messages ({what})", False
    if not (data_end and footer):
        return False, stats, "the file has no data end or footer record", True
    return True, stats, None, False


def indexed_pass(path, report, stats):
    """Reads a complete file through its summary section and indexes, decoding every message."""
    with open(path, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory(), Ros2DecoderFactory()])
        summary = reader.get_summary()
        if summary is None:
            raise Failure("the file has a footer but no summary section")
        report["summary_section"] = True
        counts = {}
        joints = report["joints"]
        for schema, channel, message, decoded in reader.iter_decoded_messages(log_time_order=True):
            counts[channel.topic] = counts.get(channel.topic, 0) + 1
            if schema.name == "sensor_msgs/msg/JointState":
                # per topic and joint name: the largest |effort| (e.g. a pack body's load, N)
                by_name = joints.setdefault(channel.topic, {})
                for name, effort in zip(decoded.name, decoded.effort):
                    by_name[name] = max(by_name.get(name, 0.0), abs(effort))
        for topic, t in report["topics"].items():
            if counts.get(topic, 0) != t["count"]:
                raise Failure(
                    f"{topic}: {counts.get(topic, 0)} messages through the indexes, "
                    f"{t['count']} in the data section"
                )
        if summary.statistics is not None:
            by_id = {c.id: c.topic for c in summary.channels.values()}
            for cid, n in summary.statistics.channel_message_counts.items():
                topic = by_id.get(cid, f"channel {cid}")
                if report["topics"].get(topic, {}).get("count", 0) != n:
                    raise Failure(f"{topic}: the statistics count {n} messages")
            if summary.statistics.message_count != report["messages"]:
                raise Failure(
                    f"the statistics count {summary.statistics.message_count} messages, "
                    f"the data section holds {report['messages']}"
                )


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("file")
    ap.add_argument("--json", action="store_true", help="print one JSON object on stdout")
    ap.add_argument(
        "--allow-truncated",
        action="store_true",
        help="a file that ends early (a killed run) is not a failure",
    )
    ap.add_argument(
        "--expect-schema",
        action="append",
        default=[],
        metavar="TOPIC=SCHEMA",
        help="require this schema name on this topic (repeatable)",
    )
    args = ap.parse_args()
    expected = dict(REQUIRED_SCHEMAS)
    for e in args.expect_schema:
        if "=" not in e:
            ap.error(f"--expect-schema {e!r}: expected TOPIC=SCHEMA")
        topic, schema = e.split("=", 1)
        expected[topic] = schema

    report = {
        "file": args.file,
        "complete": False,
        "summary_section": False,
        "truncated": False,
        "messages": 0,
        "error": None,
        "topics": {},
        "metadata": [],
        "attachments": [],
        "summary": None,
        "joints": {},
    }
    failure = None
    try:
        check_magic(args.file)
        complete, stats, error, truncated = stream_pass(args.file, report)
        report["complete"] = complete
        report["truncated"] = truncated
        report["error"] = error
        if complete:
            indexed_pass(args.file, report, stats)
        elif not (truncated and args.allow_truncated):
            failure = error
        for topic, schema in expected.items():
            got = report["topics"].get(topic, {}).get("schema")
            if got is not None and got != schema:
                raise Failure(f"{topic} has schema {got!r}, expected {schema!r}")
            if got is None and topic not in REQUIRED_SCHEMAS:
                raise Failure(f"no topic {topic}")
    except Failure as e:
        failure = str(e)
    except OSError as e:
        failure = f"cannot read: {e}"
    if failure is not None:
        report["error"] = failure

    if args.json:
        print(json.dumps(report, indent=1, sort_keys=True))
    else:
        state = "complete" if report["complete"] else ("TRUNCATED" if report["truncated"] else "DAMAGED")
        print(f"{args.file}: {report['messages']} messages decoded, {state}")
        for topic, t in sorted(report["topics"].items()):
            print(f"  {topic:<30} {t['schema']:<28} {t['count']:>9}")
        if report["error"]:
            print(f"  note: {report['error']}")
    if failure is not None:
        print(f"read_mcap.py: {args.file}: {failure}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
