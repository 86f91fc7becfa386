"""Bytes in and out of log files: the compression told by the first bytes,
a file's bytes and UTF-8 text (whole, or streamed in bounded memory), and
for the writers temporary names, copying and the context manager that
removes a half-written file."""
import io as _io
import lzma
import os

from pyins.logs.issues import LogError
from pyins.logs.options import COMPRESSIONS

TEXT_CHUNK_BYTES = 1 << 20   #: bytes read at a time from a text log


def compression_of(path):
    """The compression of the file at ``path`` from its first bytes ("gzip", "xz",
    "bzip2"), else None; the extension does not decide (a .gz that is plain
    text is read as plain text)."""
    with open(path, "rb") as f:
        head = f.read(6)
    for name, magic, _ in COMPRESSIONS.values():
        if head.startswith(magic):
            return name
    return None


def _what_bytes(path, comp):
    """How the bytes of a text log were read, for a decoding error: after a
    decompression, or as plain text although the name says compressed."""
    if comp:
        return f"after {comp} decompression, "
    ext = os.path.splitext(os.fspath(path))[1].lower()
    if ext in COMPRESSIONS:
        return f"not a {COMPRESSIONS[ext][0]} file (named {ext}, its first bytes are not), read as plain text: "
    return ""


def _opener(path):
    comp = compression_of(path)
    for name, _, opener in COMPRESSIONS.values():
        if name == comp:
            return comp, opener
    return None, open


def _read_bytes(path, name):
    """The whole file, decompressed; a broken stream is a LogError."""
    comp, opener = _opener(path)
    try:
        with opener(path, "rb") as f:
            return f.read()
    except (OSError, EOFError, lzma.LZMAError, ValueError) as exc:
        if comp is None:
            raise
        raise LogError(f"{name}: not a complete {comp} stream ({exc}): the file is cut or "
                       f"damaged") from None


def _decode(raw, path, name, strip=True):
    """The UTF-8 text of a file's bytes; not UTF-8 is a LogError naming the byte."""
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        what = _what_bytes(path, compression_of(path))
        raise LogError(f"{name}: {what}byte offset {exc.start}: not UTF-8 text (a binary log? "
                       f"pass fmt='binary')") from None
    return text.lstrip("\ufeff") if strip else text


def _text_lines(path, name):
    """(1-based line number, line) of a text file, decompressed, UTF-8, read whole."""
    text = _decode(_read_bytes(path, name), path, name)
    return enumerate(_io.StringIO(text, newline=None), start=1)


def _full(size):
    return size is None


def _read_exact(f, n, comp, name):
    """Up to ``n`` bytes (fewer only at the end; None: all); a broken stream is a LogError."""
    parts, got = [], 0
    while n is None or got < n:
        try:
            raw = f.read() if n is None else f.read(n - got)
        except (OSError, EOFError, lzma.LZMAError, ValueError) as exc:
            if comp is None:
                raise
            raise LogError(f"{name}: not a complete {comp} stream ({exc}): the file is cut or "
                           f"damaged") from None
        if not raw:
            break
        if n is None:
            return raw
        parts.append(raw)
        got += len(raw)
    return b"".join(parts)


def _stream_lines(path, name):
    """(1-based line number, line) of a text file, decompressed, UTF-8, read
    TEXT_CHUNK_BYTES at a time: `_text_lines` in bounded memory. Chunks are cut
    after a b"\\n" (never inside a UTF-8 sequence or a \\r\\n pair), so the lines
    and the byte offset of a decoding error are those of the whole file."""
    comp, opener = _opener(path)
    offset, carry, first, lineno = 0, b"", True, 0
    with opener(path, "rb") as f:
        while True:
            raw = _read_exact(f, TEXT_CHUNK_BYTES, comp, name)
            buf = carry + raw
            if raw:
                cut = buf.rfind(b"\n") + 1
                if cut == 0:
                    carry = buf
                    continue
                piece, carry = buf[:cut], buf[cut:]
            else:
                piece, carry = buf, b""
            if piece:
                try:
                    text = piece.decode("utf-8")
                except UnicodeDecodeError as exc:
                    what = _what_bytes(path, comp)
                    raise LogError(f"{name}: {what}byte offset {offset + exc.start}: not UTF-8 "
                                   f"text (a binary log? pass fmt='binary')") from None
                if first:
                    text, first = text.lstrip("\ufeff"), False
                for line in _io.StringIO(text, newline=None):
                    lineno += 1
                    yield lineno, line
                offset += len(piece)
            if not raw:
                return


def _lines(path, name, size):
    """The lines of a text log: the whole file decoded first when read whole
    (`read_log`: a decoding error anywhere comes first, as it always did),
    else streamed."""
    return _text_lines(path, name) if _full(size) else _stream_lines(path, name)


# ---------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------
COPY_BYTES = 1 << 22     #: bytes copied at a time (assembling an npz, compressing)


def _tmp_name(path, what="tmp"):
    return f"{os.fspath(path)}.{what}{os.getpid()}"


def _remove(*paths):
    for p in paths:
        if p and os.path.exists(p):
            os.remove(p)


def _copy(src, dst):
    while True:
        chunk = src.read(COPY_BYTES)
        if not chunk:
            return
        dst.write(chunk)


class _Closing:
    """A writer as a context manager: `close` when the block ends, `abort`
    when it raises (nothing half-written keeps the final name)."""

    def __enter__(self):
        return self

    def __exit__(self, exc_type, *exc):
        if exc_type is None:
            self.close()
        else:
            self.abort()
