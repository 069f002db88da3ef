"""Compress every sequence under a directory on a Dask cluster.

    python -m dmc.batch ROOT -o OUT [--scheduler ADDRESS] [--workers N] [--option NAME=VALUE ...]

One task per sequence, each on a Dask worker: read the sequence, encode it with dmc.encode (the
options of `dmc encode`, `--option residual_bits=12`), measure KG and STED, write
OUT/<path under ROOT>.dmc atomically (a temporary file, then a rename). Without --scheduler a
LocalCluster of --workers processes runs on this machine; with it, the tasks go to that
scheduler's workers, which must import dmc and see ROOT and OUT at the same paths (a shared file
system).

Sequences (symbolic links followed): every .pc2 cache (its triangles from the mesh file beside it), every .glb/.gltf file
(its motion, as `dmc encode --no-scene` codes it), and every directory holding .obj/.off/.ply frames and no
.pc2 (the frames, in natural order).

The manifest, OUT/manifest.jsonl, has one JSON object per input: input, output, bytes, bpfv, kg,
sted, seconds and error (null on success; the dmc error code and message otherwise, so one bad
file never stops the batch). It is rewritten atomically after every finished task, so it always
holds whole lines. A second run with the same OUT skips the inputs the manifest records as done
whose output still exists (resumable); --force redoes them.
"""

import argparse
import json
import os
import sys
import tempfile
import time

MANIFEST = "manifest.jsonl"
FRAME_EXTENSIONS = (".obj", ".off", ".ply")
FILE_EXTENSIONS = (".pc2", ".glb", ".gltf")


def find_sequences(root):
    """The inputs under root, sorted: .pc2, .glb and .gltf files, and frame directories."""
    found = []
    for directory, subdirectories, files in os.walk(root, followlinks=True):
        subdirectories.sort()
        names = sorted(f for f in files if not f.startswith("."))
        lower = [n.lower() for n in names]
        found += [os.path.join(directory, n) for n, l in zip(names, lower)
                  if l.endswith(FILE_EXTENSIONS)]
        has_cache = any(l.endswith(".pc2") for l in lower)
        if not has_cache and any(l.endswith(FRAME_EXTENSIONS) for l in lower):
            found.append(directory)
    return sorted(found)


def output_path(root, output_root, source):
    relative = os.path.relpath(source, root)
    stem = os.path.splitext(relative)[0] if os.path.isfile(source) else relative
    if stem in (".", ""):
        stem = os.path.basename(os.path.abspath(root))
    return os.path.join(output_root, stem + ".dmc")


def encode_one(source, output, options):
    """The task: one sequence to one stream. Returns the manifest record; never raises."""
    import dmc  # on the worker

    start = time.perf_counter()
    record = {"input": source, "output": output, "bytes": None, "bpfv": None, "kg": None,
              "sted": None, "seconds": None, "error": None}
    try:
        frames, faces, metadata = dmc.read_sequence(source, metadata=True)
        stream, report = dmc.encode(frames, faces, name=metadata["name"],
                                    frame_rate=metadata["frame_rate"], return_report=True,
                                    **options)
        os.makedirs(os.path.dirname(output) or ".", exist_ok=True)
        handle, temporary = tempfile.mkstemp(dir=os.path.dirname(output) or ".",
                                             prefix=".dmc-batch-", suffix=".tmp")
        try:
            with os.fdopen(handle, "wb") as out:
                out.write(stream)
            os.replace(temporary, output)
        except BaseException:
            os.unlink(temporary)
            raise
        record.update(bytes=report["bytes"], bpfv=report["bpfv"], kg=report["kg"],
                      sted=report["sted"])
    except dmc.Error as error:
        record["error"] = {"code": error.code_name, "message": error.message}
    except Exception as error:  # a bad file must not stop the batch
        record["error"] = {"code": type(error).__name__, "message": str(error)}
    record["seconds"] = round(time.perf_counter() - start, 3)
    return record


def read_manifest(path):
    records = {}
    if os.path.exists(path):
        with open(path, encoding="utf-8") as manifest:
            for line in manifest:
                if line.strip():
                    record = json.loads(line)
                    records[record["input"]] = record
    return records


def write_manifest(path, records):
    """All records, one JSON line each, in input order; atomically (temporary file, rename)."""
    handle, temporary = tempfile.mkstemp(dir=os.path.dirname(path) or ".", prefix=".manifest-",
                                         suffix=".tmp")
    with os.fdopen(handle, "w", encoding="utf-8") as out:
        for source in sorted(records):
            out.write(json.dumps(records[source], sort_keys=True) + "\n")
    os.replace(temporary, path)


def parse_option(text):
    name, separator, value = text.partition("=")
    if not separator or not name:
        raise argparse.ArgumentTypeError(f"expected NAME=VALUE, got {text!r}")
    try:
        return name, json.loads(value)
    except json.JSONDecodeError:
        return name, value  # a bare string: operator=tutte


def run(root, output_root, client, options=None, force=False, log=print):
    """Encodes every sequence under root with the Dask client; returns the manifest records."""
    from distributed import as_completed

    options = dict(options or {})
    root = os.path.abspath(root)
    output_root = os.path.abspath(output_root)
    os.makedirs(output_root, exist_ok=True)
    manifest = os.path.join(output_root, MANIFEST)
    records = read_manifest(manifest)
    pending = []
    for source in find_sequences(root):
        if os.path.commonpath([source, output_root]) == output_root:
            continue  # never an output of ours
        output = output_path(root, output_root, source)
        done = records.get(source)
        if not force and done and done["error"] is None and os.path.exists(done["output"]):
            continue
        pending.append((source, output))
    log(f"dmc.batch: {len(pending)} to encode; {manifest} records {len(records)}")
    futures = [client.submit(encode_one, source, output, options, key=f"dmc-encode-{source}",
                             pure=False) for source, output in pending]
    for future in as_completed(futures):
        record = future.result()
        records[record["input"]] = record
        write_manifest(manifest, records)
        if record["error"]:
            log(f"dmc.batch: {record['input']}: {record['error']['code']}: "
                f"{record['error']['message']}")
        else:
            log(f"dmc.batch: {record['input']}: {record['bytes']} bytes, {record['bpfv']:.4f} bpfv,"
                f" STED {record['sted']}, {record['seconds']} s")
    return records


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m dmc.batch", description=__doc__.split("\n\n")[0])
    parser.add_argument("root", help="directory holding the sequences")
    parser.add_argument("-o", "--output", required=True, help="output directory (and manifest)")
    parser.add_argument("--scheduler", help="address of a running Dask scheduler "
                        "(default: a LocalCluster on this machine)")
    parser.add_argument("--workers", type=int, default=0,
                        help="LocalCluster worker processes (default: one per core)")
    parser.add_argument("--option", action="append", type=parse_option, default=[],
                        metavar="NAME=VALUE", help="a dmc.encode option, e.g. residual_bits=12")
    parser.add_argument("--force", action="store_true", help="redo inputs already done")
    args = parser.parse_args(argv)
    if not os.path.isdir(args.root):
        parser.error(f"{args.root} is not a directory")
    import dmc
    from distributed import Client, LocalCluster

    known = {o["name"] for o in dmc.encoder_options()}
    for name, _ in args.option:
        if name not in known:
            parser.error(f"--option {name}: not an encoder option (dmc.encoder_options())")
    if args.scheduler:
        client = Client(args.scheduler)
    else:
        workers = args.workers or os.cpu_count() or 1
        client = Client(LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                     dashboard_address=None))
    with client:
        records = run(args.root, args.output, client, dict(args.option), args.force)
    failed = [r for r in records.values() if r["error"]]
    print(f"dmc.batch: {len(records) - len(failed)} done, {len(failed)} failed; "
          f"manifest {os.path.join(os.path.abspath(args.output), MANIFEST)}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
