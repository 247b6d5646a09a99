"""Build CAD files for the outline tests (imported by bare name)."""


def dxf_file(path, build, insunits=4):
    """Write a DXF at ``path`` whose modelspace ``build(msp)`` fills, with the
    header's ``$INSUNITS`` (4: mm); returns the path."""
    import ezdxf
    doc = ezdxf.new()
    doc.header["$INSUNITS"] = insunits
    build(doc.modelspace())
    doc.saveas(path)
    return path
