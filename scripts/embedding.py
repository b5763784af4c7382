"""What scripts/embed-stdlib and scripts/embed-text share: bytes as a C
char array initializer, and writing a generated file only when it changes."""
import os


def c_bytes(data):
    """A char array initializer: immune to any character the source contains.
    Bytes as signed char values, so UTF-8 text (bytes >= 128) embeds too."""
    out = []
    for i in range(0, len(data), 20):
        out.append("  " + ", ".join(str(b - 256 if b > 127 else b) for b in data[i:i + 20]) + ",")
    return "\n".join(out)


def write_if_changed(out_path, text):
    """Write text to out_path unless it holds it already, so that make does
    not rebuild what depends on it needlessly."""
    if os.path.exists(out_path):
        with open(out_path) as f:
            if f.read() == text:
                return
    os.makedirs(os.path.dirname(out_path), exist_ok=True)
    with open(out_path, "w") as f:
        f.write(text)
