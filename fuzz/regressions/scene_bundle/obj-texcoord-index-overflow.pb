
s.xmlj
s.xmla<scene version="0.5.0"><shape type="obj"><string name="filename" value="m.obj"/></shape></scene>
/
m.obj&v 0 0 0
vt 0 0
f 1/1 1/1 1/1073741825
