
s.xmlj
s.xmla<scene version="0.5.0"><shape type="obj"><string name="filename" value="m.obj"/></shape></scene>
3
m.obj*v 0 0 0
vn 0 0 1
f 1//1 1//1 1//715827883
